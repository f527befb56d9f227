"""SI units of metrics and scene parameters as plain text, for the terminal and for text files.

Figures draw values in engineering units with matplotlib labels (mm, kN, ``mm$^2$``:
:mod:`mbs_models.results.sweep_plots`); text output instead gives every value in the SI unit the user
types on the command line (``--vary contact.gap=0:0.12``, ``--constraint peak_support_force<=7000``), with
a plain unit string (``m``, ``N``, ``m^2``): one unit system, and no plot markup on a terminal.  A scene
field's unit is the one its table's rule names (the unit of the scene file).
"""

from __future__ import annotations

#: Metric (the last component of a sweep column: ``absorber.0.peak_contact_force`` is a
#: ``peak_contact_force``) -> its SI unit.  ``time_of_*`` metrics are in s.
METRIC_SI_UNITS = {
    "max_barrel_displacement": "m", "peak_support_force": "N", "peak_contact_force": "N",
    "max_absorber_velocity": "m/s", "impacts": "count", "dissipated_energy": "J",
    "initial_velocity": "m/s", "end_time": "s", "steps": "count", "wall_time": "s",
    "max_carriage_pitch": "rad", "max_lift": "m", "lift_off_time": "s", "max_carriage_displacement": "m",
    "stability_margin": "-", "min_normal_force": "N",
}

#: Scene fields whose table gives no unit in its rules (:class:`~mbs_models.elements.table.Rule`): a
#: number or a table of numbers in these units.
UNRULED_PARAMETER_UNITS = {"orifice_area": "m^2", "counter_recoil_orifice_area": "m^2", "shots": "count"}


def metric_si_unit(column: str) -> str:
    """The SI unit of a metric column (``max_barrel_displacement`` -> ``m``, ``time_of_...`` -> ``s``,
    ``absorber.0.peak_contact_force`` -> ``N``, a declared metric's declared unit); ``SI`` for a column not
    listed."""
    from .element_outputs import declared_column_unit

    declared = declared_column_unit(column)
    if declared is not None:
        return declared
    name = column.rsplit(".", 1)[-1]
    if name.startswith("time_of_"):
        return "s"
    return METRIC_SI_UNITS.get(name, "SI")


def parameter_si_unit(key: str) -> str:
    """The SI unit of a dotted scene key, as its table's rule states it (``contact.gap`` -> ``m``,
    ``absorber.1.contact.stiffness`` -> ``N/m^exponent``, ``-`` for a dimensionless field); ``SI`` for a
    key that names no field of a known table."""
    from ..elements import TABLES

    parts = [part for part in key.split(".") if not part.isdigit()]
    field = parts[-1]
    table = TABLES.get(parts[-2]) if len(parts) > 1 else None
    rule = table.RULES.get(field) if table is not None else None
    if rule is not None:
        return rule.unit or "-"
    return UNRULED_PARAMETER_UNITS.get(field, "SI")


__all__ = ["METRIC_SI_UNITS", "UNRULED_PARAMETER_UNITS", "metric_si_unit", "parameter_si_unit"]
