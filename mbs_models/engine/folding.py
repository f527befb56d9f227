"""Which connectors share one Exudyn item: connectors between the same two points are folded into one.

Every connector is an ``ObjectConnectorCoordinateSpringDamper`` between its two markers
(:meth:`~mbs_models.elements.connector.Connector.add_items`), and Exudyn's explicit solvers evaluate every item at
every stage of every step: two items between the same markers cost two evaluations where one would do (the
paper's recoil spring and asymmetric recoil damper both act between the ground and the barrel).  So the
connectors with the same ends ``(a, b)`` whose item is the plain connector item (``add_items`` and
``update_items`` not overridden) and whose force no sensor records (contacts record theirs) are one item
(:func:`connector_items`), whose force is the sum of theirs::

    all built-in linear:   F = k d + c d'                         Exudyn's linear law, k = sum k_i, c = sum c_i
    else:                  F = F_1(d, d') + ... + F_n(d, d') + k d + c d'
                                                                  one user function: the members' laws in
                                                                  element order, then the linear members'
                                                                  summed coefficients (terms of 0 left out)

The same force as one item per connector, to round-off: only the order of the additions differs (Exudyn adds
each item's force to the residual; here the members' forces are added first).  A connector alone on its ends is
its own item, made by its own ``add_items`` exactly as before.  An element the scene lacks has no connector, so
it still adds no item.  The grouping depends only on what :func:`~mbs_models.engine.assembly.structure_key`
holds (the connectors' classes, ends, user functions and force sensors), so a refilled system
(:func:`~mbs_models.engine.assembly.refill`) has the same items.
"""

from __future__ import annotations

from typing import Sequence

from ..elements.connector import Connector, add_connector_item, record_spring_force_law
from ..elements.ops import ops_for
from .law_state import same_laws


def foldable(connector: Connector) -> bool:
    """True if ``connector`` may share its item: the plain connector item (``add_items`` and ``update_items`` of
    :class:`~mbs_models.elements.connector.Connector`), no force sensor on it and no offset held by the item (one
    item has one offset)."""
    kind = type(connector)
    return (not connector.records_force and not connector.offset_in_item and kind.add_items is Connector.add_items
            and kind.update_items is Connector.update_items)


def connector_items(connectors: Sequence[Connector]) -> list[tuple[Connector, ...]]:
    """The connectors grouped by the Exudyn item they share, in the order of each group's first member: the
    :func:`foldable` connectors with the same ``(a, b)`` together, every other connector alone."""
    items: list[list[Connector]] = []
    shared: dict[tuple[str, str], list[Connector]] = {}
    for connector in connectors:
        group = shared.get((connector.a, connector.b)) if foldable(connector) else None
        if group is None:
            group = [connector]
            items.append(group)
            if foldable(connector):
                shared[(connector.a, connector.b)] = group
        else:
            group.append(connector)
    return [tuple(group) for group in items]


def linear_part(members: Sequence[Connector]) -> tuple[float, float]:
    """``(k N/m, c N s/m)``: the summed built-in coefficients of the members without a user function."""
    stiffness = damping = 0.0
    for member in members:
        if not member.needs_user_function:
            k, c = member.builtin_coefficients()
            stiffness += k
            damping += c
    return stiffness, damping


def folded_law(members: Sequence[Connector], ops):
    """``f(d, rate) -> F`` (N) over ``ops``: the folded item's force (module docstring)."""
    laws = [member.user_function_law(ops) for member in members if member.needs_user_function]
    stiffness, damping = linear_part(members)

    def law(d, rate):
        force = laws[0](d, rate)
        for other in laws[1:]:
            force = force + other(d, rate)
        if stiffness:
            force = force + stiffness * d
        if damping:
            force = force + damping * rate
        return force

    return law


def add_item(mbs, members: Sequence[Connector], marker_a, marker_b, user_functions: str = "symbolic"):
    """Add the Exudyn item of ``members`` (one group of :func:`connector_items`) between two coordinate markers;
    return its ObjectIndex (also each member's ``index``)."""
    if len(members) == 1:
        return members[0].add_items(mbs, marker_a, marker_b, user_functions)
    index = add_connector_item(mbs, marker_a, marker_b)
    _fill(mbs, index, members, user_functions)
    return index


def update_item(mbs, index, members: Sequence[Connector], user_functions: str = "symbolic",
                recorded: Sequence[Connector] | None = None) -> None:
    """Write the numbers of ``members`` into ``index``, the item :func:`add_item` made for a group of the same
    classes and ends (:func:`~mbs_models.engine.assembly.refill`).

    ``recorded``: the connectors the item holds now (the previous point's, in the order of ``members``), or None.
    Where they are plain connectors (``update_items`` not overridden) with the same laws by value
    (:func:`~mbs_models.engine.law_state.same_laws`) and the user functions are symbolic, the item already is what
    this function would write: it is left as it is and its recorded user function passes to ``members``."""
    if (recorded is not None and user_functions == "symbolic"
            and all(type(member).update_items is Connector.update_items for member in members)
            and same_laws(recorded, members)):
        for old, new in zip(recorded, members):
            if "_user_function" in vars(old):
                new._user_function = old._user_function
            if new.offset_in_item:  # (the one number the law takes from the item: Connector.update_items writes it)
                mbs.SetObjectParameter(index, "offset", new.offset)
            new.index = index
        return
    if len(members) == 1:
        members[0].update_items(mbs, index, user_functions)
        return
    _fill(mbs, index, members, user_functions)


def _fill(mbs, index, members: Sequence[Connector], user_functions: str) -> None:
    """The folded item's law: Exudyn's linear law of the summed coefficients, or one user function of all."""
    if any(member.needs_user_function for member in members):
        mbs.SetObjectParameter(index, "stiffness", 0.0)
        mbs.SetObjectParameter(index, "damping", 0.0)
        keeper = next(member for member in members if member.needs_user_function)
        keeper._user_function = record_spring_force_law(mbs, index, folded_law(members, ops_for(user_functions)),
                                                        user_functions)
    else:
        stiffness, damping = linear_part(members)
        mbs.SetObjectParameter(index, "stiffness", stiffness)
        mbs.SetObjectParameter(index, "damping", damping)
    for member in members:
        member.index = index


__all__ = ["foldable", "connector_items", "linear_part", "folded_law", "add_item", "update_item"]
