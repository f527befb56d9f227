"""The element registry (mbs_models/elements/__init__.py): register_element's refusals and its idempotence.

A successful registration from outside the package changes the registry of the process: it is tested in a
fresh process with the out-of-tree example (tests/examples/test_progressive_spring.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import pytest

import mbs_models
from mbs_models.elements import ELEMENT_TABLES, TABLES, Table, register_element
from mbs_models.elements.recoil_spring import RecoilSpring
from validation.reference.terms import TERMS, register_term


def test_register_element_is_public_and_idempotent():
    before = dict(TABLES), dict(ELEMENT_TABLES)
    assert mbs_models.register_element is register_element
    assert register_element(RecoilSpring) is RecoilSpring
    assert (dict(TABLES), dict(ELEMENT_TABLES)) == before
    assert list(TABLES) == list(before[0])  # the order too


def test_a_taken_table_name_is_refused():
    @dataclass(frozen=True)
    class OtherSpring(Table):
        stiffness: float
        TABLE: ClassVar[str] = "recoil_spring"

    with pytest.raises(TypeError, match="'recoil_spring' of OtherSpring is taken"):
        register_element(OtherSpring)
    assert TABLES["recoil_spring"] is RecoilSpring


@pytest.mark.parametrize("name", ["conventions", "contact", "version", "name"])
def test_a_scene_key_is_no_table_name(name):
    table = dataclass(frozen=True)(type("Clash", (Table,), {"__annotations__": {"x": float}, "TABLE": name}))
    with pytest.raises(TypeError, match="taken"):
        register_element(table)


@pytest.mark.parametrize("thing", [int, RecoilSpring(1.0), type("NotADataclass", (Table,), {"TABLE": "x"})])
def test_register_element_needs_a_table_dataclass(thing):
    with pytest.raises(TypeError, match="dataclass subclass"):
        register_element(thing)


def test_register_term_refusals_and_idempotence():
    shipped = TERMS["recoil_spring"]
    assert register_term(shipped) is shipped
    with pytest.raises(TypeError, match="already has a reference term"):
        register_term(type("Clash", (), {"TABLES": ("recoil_spring",), "build": staticmethod(lambda b, k, t: None)}))
    with pytest.raises(TypeError, match="needs TABLES"):
        register_term(type("NoBuild", (), {"TABLES": ("something",)}))
    assert TERMS["recoil_spring"] is shipped and "something" not in TERMS
