"""Why a run ended: :class:`StopReason`, the value of :attr:`Result.stop_reason <mbs_models.results.result.Result>`.

Every way :func:`~mbs_models.simulate` ends a run is one member here, with a one-line message for people
(:attr:`StopReason.message`).  A member *is* its string (:class:`enum.StrEnum`): JSON (``recoil run --json``),
sweep tables and CSV files write the same text as before the enumeration existed (``"end_time"``,
``"metrics_final"``...), ``reason == "at_rest"`` holds, and ``StopReason("at_rest")`` reads a value back from an
old table.  The reference (:mod:`validation.reference`) names its own stop reasons independently.
"""

from __future__ import annotations

from enum import StrEnum


class StopReason(StrEnum):
    """How a run ended; the value is the string written to JSON and tables, :attr:`message` says it in words."""

    #: Integrated to the requested end time (no early stop asked for, or none proven).
    END_TIME = "end_time", "reached the end of the window"
    #: Every metric named in ``stop_when_final`` was proven final by energy bounds before the end time.
    METRICS_FINAL = "metrics_final", "every metric asked for is final (proven by energy bounds)"
    #: An early stop was asked for, but the scene injects energy (no bound): run to the end time.
    NO_ENERGY_BOUND = "end_time_no_energy_bound", "reached the end of the window: the scene has no energy bound"
    #: Stopped early, but the solution's energy rose by more than the bounds' slack: re-solved to the end time.
    ENERGY_CHECK = ("end_time_energy_check",
                    "reached the end of the window: the early stop failed the energy check and was re-solved")
    #: Proven within the tolerance of the rest state: the rest state is held to the end time.
    AT_REST = "at_rest", "at rest (energy bounds): the rest state is held to the end of the window"

    def __new__(cls, value: str, message: str):
        member = str.__new__(cls, value)
        member._value_ = value
        member.message = message
        return member
