"""What an element declares about its outputs: its histories and scalar metrics, and where each appears.

An element's table says it once, as the class attribute ``OUTPUTS`` (an :class:`Outputs`), and the engine, the
:class:`~mbs_models.results.result.Result`, ``recoil run --json`` / ``--plot``, ``recoil run``'s summary and the
sweeps take it from there (:mod:`mbs_models.results.element_outputs`); no module outside the element names
them::

    OUTPUTS: ClassVar = Outputs(
        histories=(History("force", "N", lambda run: run.force(), panel="spring force [kN]", scale=1e-3),),
        metrics=(Metric("peak_force", "N", lambda run: float(np.max(np.abs(run.history("force"))))),))

* a :class:`History` ``name`` (unit ``unit``) is ``compute(run)``: an array, one value per output time of the
  run (``run.time``), from the run's samples (:class:`ElementRun`); ``panel``: the y-label of its plot panel in
  ``recoil run --plot`` (values times ``scale``), None for none;
* a :class:`Metric` ``name`` (unit ``unit``) is ``compute(run)``: a scalar reduced from the element's histories
  (``run.history(name)``) or the run's samples, or any JSON-ready value (a list of dicts); it appears in
  ``Result.element_metrics[element][name]``, in ``recoil run --json`` under the element's block
  (``{"progressive_spring": {"peak_force": ...}}``, or at the top level under ``json_key``), as the sweep column
  ``<element>.<name>`` when ``column`` (a finite number, N, m, s...), and as lines
  of ``recoil run``'s summary (``summary(value)``, default one line ``<element> <name> value unit``).

An element's roles (``ROLES``, a tuple of :data:`ABSORBER`, :data:`END_STOP`) say what it is to the results: the
bodies and contacts of an :data:`ABSORBER` are the absorbers of the version-1 metrics (``peak_contact_force``,
``max_absorber_velocity``, ``impacts``; ``Result.absorbers()``); the contacts of an :data:`END_STOP` are its
stops (``Result.stops()``, the sweep columns ``<stop>.peak_contact_force`` ...).  A connector says itself whether it
is a contact (``Connector.is_contact``: its force history and impacts are outputs).

A metric describes the window simulated; after an early stop (``stop_when_final``) it is None unless it says
``window=True`` (a value that is meaningful for any window, such as the shots fired in it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable


#: The role of an element whose bodies are absorbers (and whose contacts are the absorbers' contacts).
ABSORBER = "absorber"
#: The role of an element whose contacts are end stops (contacts the barrel hits, on the ground).
END_STOP = "end_stop"


def elements_with(scene, role: str) -> list[str]:
    """The names of the elements of ``scene`` that declare ``role`` (their table's ``ROLES``), in element order."""
    return [name for name, table in scene.elements() if role in getattr(table, "ROLES", ())]


@dataclass(frozen=True)
class History:
    """A time history an element declares: ``name``, SI ``unit``, ``compute(run) -> array`` (one value per output
    time), ``panel``: the y-label of its own panel in ``recoil run --plot`` (values times ``scale``; None: not
    plotted)."""

    name: str
    unit: str
    compute: Callable[[Any], Any]
    panel: str | None = None
    scale: float = 1.0


@dataclass(frozen=True)
class Metric:
    """A scalar metric (or a JSON-ready value) an element declares: ``name``, SI ``unit``, ``compute(run)``; ``json_key``: a top-level key of ``recoil run --json`` instead of the element's
    block; ``column``: a sweep column ``<element>.<name>`` (a number); ``summary(value) -> lines`` of the run's
    summary (None: one line with the value and unit); ``window``: reported after an early stop too."""

    name: str
    unit: str
    compute: Callable[[Any], Any]
    json_key: str | None = None
    column: bool = True
    summary: Callable[[Any], list[str]] | None = None
    window: bool = False


@dataclass(frozen=True)
class Outputs:
    """An element's declared outputs: its :class:`History` and :class:`Metric` specs, in report order."""

    histories: tuple[History, ...] = ()
    metrics: tuple[Metric, ...] = ()

    def __bool__(self) -> bool:
        return bool(self.histories or self.metrics)


#: The outputs of an element that declares none.
NO_OUTPUTS = Outputs()


@dataclass(frozen=True)
class ElementRun:
    """What an element's outputs are computed from: its ``table`` and element ``name``, the ``scene``, the
    ``mechanism`` (:class:`~mbs_models.engine.mechanism.Mechanism`), the step-end ``samples``
    (:class:`~mbs_models.results.samples.Samples`: ``time`` s, ``positions`` m, ``velocities`` m/s,
    ``accelerations`` m/s^2 per body, ``forces`` N per contact), their cubic Hermite ``interpolant`` and the
    element's histories computed so far (``histories``, by name)."""

    table: Any
    name: str
    scene: Any
    mechanism: Any
    samples: Any
    interpolant: Any
    histories: dict

    @property
    def time(self):
        """The output times (s)."""
        return self.samples.time

    def history(self, name: str):
        """The element's declared history ``name`` (computed before this output)."""
        return self.histories[name]

    def connectors(self) -> list:
        """The element's connectors in the mechanism."""
        return [c for c in self.mechanism.connectors if c.element == self.name]

    def force(self, connector=None):
        """The force (N) of the element's connector (its only one unless named) at the output times: its law on the
        samples, ``F(d, d', t)``."""
        if connector is None:
            connectors = self.connectors()
            if len(connectors) != 1:
                raise ValueError(f"{self.name} has {len(connectors)} connectors: name one")
            connector = connectors[0]
        s = self.samples
        return connector.force(self.mechanism.relative(connector, s.positions),
                               self.mechanism.relative(connector, s.velocities), s.time)
