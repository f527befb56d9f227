"""Reading what users give (``mbs_models/inputs.py``): files of bounded size, regular and UTF-8; TOML of bounded
nesting.  Every refusal is one SceneError naming the key it is given; nothing blocks or reads without limit."""

from __future__ import annotations

import os
import sys

import pytest

from mbs_models import SceneError
from mbs_models.inputs import (MAX_TOML_NESTING, bracket_nesting, check_toml_nesting, data_nesting, parse_toml,
                               read_text_file)


def _refused(path, text: str, **kwargs) -> SceneError:
    with pytest.raises(SceneError) as info:
        read_text_file(path, "firing.pulse.file", "pulse file", **kwargs)
    assert info.value.key == "firing.pulse.file" and text in info.value.message, info.value
    assert "\n" not in str(info.value)
    return info.value


def test_a_regular_utf8_file_is_read_whole(tmp_path):
    (tmp_path / "a.csv").write_text("time,force\n0.0,1.0 # é\n", encoding="utf-8")
    assert read_text_file(tmp_path / "a.csv", "k", "pulse file") == "time,force\n0.0,1.0 # é\n"


def test_a_missing_file_and_a_directory_are_refused(tmp_path):
    _refused(tmp_path / "nothing.csv", "pulse file not found")
    _refused(tmp_path, "is a directory")


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_a_device_is_refused_without_reading_it():
    """/dev/zero never ends: it is refused on its type, before a byte is read."""
    _refused("/dev/zero", "not a regular file")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_without_a_writer_is_refused_without_blocking(tmp_path):
    """Opening a FIFO for reading waits for a writer; opened non-blocking it is refused at once."""
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    _refused(fifo, "not a regular file")


def test_a_file_larger_than_the_limit_is_refused(tmp_path):
    (tmp_path / "big.csv").write_bytes(b"x" * 101)
    _refused(tmp_path / "big.csv", "larger than 100 bytes", max_bytes=100)
    (tmp_path / "fits.csv").write_bytes(b"x" * 100)
    assert read_text_file(tmp_path / "fits.csv", "k", "pulse file", max_bytes=100) == "x" * 100


def test_a_binary_or_non_utf8_file_is_refused(tmp_path):
    (tmp_path / "nul.csv").write_bytes(b"time,force\n0.0,\x001.0\n")
    _refused(tmp_path / "nul.csv", "a binary file (a NUL byte at byte 15)")
    (tmp_path / "latin.csv").write_bytes("time,force # é\n".encode("latin-1"))
    _refused(tmp_path / "latin.csv", "not UTF-8 text (byte 13)")


def test_brackets_inside_strings_and_comments_do_not_nest():
    assert bracket_nesting('a = [[1, 2], [3]]\n[[absorber]]\n[absorber.contact]\n') == 2
    assert bracket_nesting('a = "[[[["  # [[[[[\nb = \'[[\'\nc = """ [[[ \\""" ]"""\nd = \'\'\'[[[\'\'\'\n') == 0
    assert bracket_nesting("x = " + "[" * 40 + "]" * 40) == 40
    assert bracket_nesting("x = " + "{a = " * 3 + "1" + "}" * 3) == 3


def test_data_nesting_counts_levels_without_recursion():
    deep: dict = {}
    node = deep
    for _ in range(sys.getrecursionlimit() * 2):  # deeper than a recursive walk could go
        node["a"] = {}
        node = node["a"]
    assert data_nesting(deep) == sys.getrecursionlimit() * 2 + 1
    assert data_nesting({"a": [1, [2]], "b": 3}) == 3 and data_nesting(5) == 0


@pytest.mark.parametrize("depth", [MAX_TOML_NESTING + 1, 1000, 100_000])
def test_arrays_and_inline_tables_nested_too_deep_are_refused_before_parsing(depth):
    """The parser recurses once per level (a RecursionError near 1000): the depth is checked first."""
    for text in ("x = " + "[" * depth + "]" * depth, "x = " + "{a = " * depth + "1" + "}" * depth):
        with pytest.raises(SceneError, match=f"nested more than {MAX_TOML_NESTING} deep") as info:
            parse_toml(text, "", "scene.toml")
        assert info.value.key == "" and "scene.toml" in str(info.value)


def test_nesting_up_to_the_limit_is_parsed():
    depth = MAX_TOML_NESTING
    assert data_nesting(parse_toml("x = " + "[" * depth + "]" * depth, "", "s")) == depth + 1
    check_toml_nesting("[" * depth + "]" * depth, "contact.gap", "the value")


def test_tables_nested_too_deep_by_dotted_keys_are_refused_after_parsing():
    """Dotted keys nest tables without brackets (and without the parser's recursion): checked on the data.  A key
    of n parts nests n - 1 tables in the document."""
    text = ".".join(["a"] * (MAX_TOML_NESTING + 2)) + " = 1\n"
    with pytest.raises(SceneError, match="dotted keys"):
        parse_toml(text, "", "scene.toml")
    assert parse_toml(".".join(["a"] * (MAX_TOML_NESTING + 1)) + " = 1\n", "", "s")


def test_malformed_toml_is_one_scene_error():
    with pytest.raises(SceneError, match="malformed TOML in scene.toml") as info:
        parse_toml("x = [1, 2", "", "scene.toml")
    assert "\n" not in str(info.value)
