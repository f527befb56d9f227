"""mbs_models/outputs.py: atomic writes with the permissions of an ordinary new file."""

from __future__ import annotations

import os
import stat

import pytest

from mbs_models.outputs import atomic_write_bytes, atomic_write_json, atomic_write_text, current_umask


@pytest.fixture
def umask():
    """Set the umask for one test and restore it afterwards."""
    saved = os.umask(0o022)
    os.umask(saved)

    def set_mask(mask: int) -> None:
        os.umask(mask)

    yield set_mask
    os.umask(saved)


@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
@pytest.mark.parametrize("write", [lambda p: atomic_write_bytes(p, b"x"), lambda p: atomic_write_text(p, "x"),
                                   lambda p: atomic_write_json(p, {"x": 1})])
def test_files_honour_the_umask(tmp_path, umask, mask, mode, write):
    umask(mask)
    assert current_umask() == mask
    path = tmp_path / "out.dat"
    write(path)
    assert stat.S_IMODE(path.stat().st_mode) == mode
    # the same as a file opened the ordinary way under that umask
    plain = tmp_path / "plain.dat"
    plain.write_bytes(b"x")
    assert stat.S_IMODE(plain.stat().st_mode) == mode


def test_rewrite_is_atomic_and_leaves_no_temporary(tmp_path, umask):
    umask(0o022)
    path = tmp_path / "out.txt"
    atomic_write_text(path, "first")
    atomic_write_text(path, "second")
    assert path.read_text() == "second"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


def test_an_output_directory_is_checked_without_being_created(tmp_path):
    from mbs_models import SceneError
    from mbs_models.outputs import check_output_dir

    assert check_output_dir(tmp_path / "a" / "b") == tmp_path / "a" / "b"
    assert not (tmp_path / "a").exists()  # nothing created
    (tmp_path / "file").write_text("x")
    with pytest.raises(SceneError, match="exists and is not a directory"):
        check_output_dir(tmp_path / "file", "--out")
    with pytest.raises(SceneError, match="is not a writable directory"):
        check_output_dir(tmp_path / "file" / "below", "--out")  # its nearest existing ancestor is a file
