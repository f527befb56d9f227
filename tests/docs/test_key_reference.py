"""The key reference covers every key of every scene table: a new key cannot go undocumented.

The expectations are the tables' own dataclass fields (what a scene file may say), independent of the
reference's parsing: every field must appear, with a description and a unit."""

import dataclasses

import pytest

from mbs_models.elements import TABLES, Rule, Table
from mbs_models.scene import Conventions
from mbs_models.scene.keys import (attribute_descriptions, key_reference, missing_declarations, table_keys)


def test_every_key_of_every_table_has_a_description_and_a_unit():
    assert missing_declarations() == []


@pytest.mark.parametrize("cls", [*dict.fromkeys(TABLES.values()), Conventions], ids=lambda cls: cls.__name__)
def test_the_reference_lists_every_field_in_order(cls):
    assert [entry.key for entry in table_keys(cls)] == [f.name for f in dataclasses.fields(cls)]


def test_every_table_appears_in_the_reference_with_its_nested_tables():
    headers = [table.header for table in key_reference()]
    for header in ("[barrel]", "[[absorber]]", "[absorber.contact]", "[recoil_brake]", "[[recoil_brake.band]]",
                   "[carriage]", "[[carriage.support]]", "[firing]", "[firing.pulse]", "[conventions]"):
        assert header in headers
    listed = {table.cls for table in key_reference()}
    assert set(TABLES.values()) <= listed


def test_a_field_without_a_declaration_is_reported():
    @dataclasses.dataclass(frozen=True)
    class Undocumented(Table):
        """A table with one documented key.

        Attributes
        ----------
        length: in m.
        """

        length: float
        width: float = 1.0
        RULES = {"length": Rule(0.0, unit="m")}

    entries = {entry.key: entry for entry in table_keys(Undocumented)}
    assert entries["length"].unit == "m" and entries["length"].description == "in m."
    assert entries["width"].unit == "" and entries["width"].description == ""
    assert entries["width"].default == "1" and entries["length"].default == "required"


def test_descriptions_are_parsed_from_the_attributes_section():
    class Doc:
        """Summary.

        Attributes
        ----------
        a, b: shared text
            continued.
        c: own text.

        Notes after the section are not a key.
        """

    assert attribute_descriptions(Doc) == {"a": "shared text continued.", "b": "shared text continued.",
                                           "c": "own text."}


def test_ranges_units_and_choices_come_from_the_declarations():
    absorber = {entry.key: entry for entry in table_keys(TABLES["absorber"])}
    assert absorber["mass"].unit == "kg" and absorber["mass"].range == "> 0"
    assert set(absorber["mount"].choices) == {"barrel", "ground"}
    brake = {entry.key: entry for entry in table_keys(TABLES["recoil_brake"])}
    assert brake["discharge_coefficient"].range == "in (0, 1]" and brake["discharge_coefficient"].unit == "1"
    assert "hunt-crossley" in {entry.key: entry for entry in table_keys(TABLES["contact"])}["law"].choices
