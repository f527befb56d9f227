"""Exceptions raised by the library.

Two kinds of failure matter to users and are kept apart:

* :class:`SceneError` -- the *input* is wrong (a bad scene file, a value out of range, an impossible
  solver setting).  It always names the offending key so the message can be shown as one line.
* :class:`SimulationError` -- the input was valid but the *solve* failed (the solver stopped early,
  produced NaN, or a user function raised).  Nothing half-finished is ever returned as a result.

A third, of the machinery rather than of a point: :class:`ClusterError` -- the Dask cluster a sweep or an
optimisation runs on failed it (its scheduler cannot be reached or was lost, no worker came); the whole run
stops (a sweep's finished rows are kept in its file).

One warning category: :class:`UnitWarning` -- the input is valid but a magnitude is implausible (a unit
slip?); the run goes on.
"""

from __future__ import annotations


class RecoilError(Exception):
    """Base class of every error raised on purpose by this library."""


class SceneError(RecoilError, ValueError):
    """A scene (or a solver setting) is invalid.

    Parameters
    ----------
    key:
        Dotted path of the offending entry, e.g. ``"contact.gap"`` (``""`` for the whole file).
    message:
        What is wrong and what would be allowed.
    """

    def __init__(self, key: str, message: str):
        self.key = key
        self.message = message
        super().__init__(f"{key}: {message}" if key else message)


class SimulationError(RecoilError, RuntimeError):
    """A solve failed; the message says why (early stop, NaN, exception in a user function...)."""


class ClusterError(RecoilError, RuntimeError):
    """The Dask cluster of a run failed: its scheduler cannot be reached or was lost, no worker has been
    available for longer than the run's ``worker_timeout``, or workers kept dying on one task.  An error of
    the whole run, never of a point (:mod:`mbs_models.studies.backends`); the message says what happened and
    what was kept."""


class UnitWarning(UserWarning):
    """A magnitude implausible for a recoil mechanism -- most likely a unit slip (a mass in tonnes, a gap
    in mm, a pulse in ms and kN).  The message names the key, the value, the plausible range and the
    likely slip; nothing is clamped or refused (:mod:`mbs_models.engine.unit_slips`)."""
