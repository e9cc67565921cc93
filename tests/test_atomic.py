"""affinity.atomic.atomic_write: whole or nothing, and never destroying what the path names.

Every node and link is made in tmp_path (the real /dev/null is never touched).
"""

import os
import stat

import pytest
from helpers.nodes import make_null_device, read_fifo_in_background

from affinity.atomic import atomic_write


def test_regular_file_is_replaced_whole_and_keeps_its_mode(tmp_path):
    path = tmp_path / "out.txt"
    path.write_text("old")
    os.chmod(path, 0o640)
    with atomic_write(path) as f:
        f.write("new\n")
    assert path.read_text() == "new\n"
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert os.listdir(tmp_path) == ["out.txt"]


def test_failure_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "out.txt"
    path.write_text("old")
    with pytest.raises(RuntimeError), atomic_write(path) as f:
        f.write("partial")
        raise RuntimeError("boom")
    assert path.read_text() == "old"
    assert os.listdir(tmp_path) == ["out.txt"]


def test_symlink_stays_a_link_and_its_target_is_replaced(tmp_path):
    (tmp_path / "real").mkdir()
    target = tmp_path / "real" / "data.png"
    target.write_bytes(b"old")
    link = tmp_path / "link.png"
    link.symlink_to(target)
    with atomic_write(link, binary=True) as f:
        f.write(b"new")
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_bytes() == b"new"
    assert sorted(os.listdir(tmp_path / "real")) == ["data.png"]


def test_dangling_symlink_creates_its_target(tmp_path):
    link = tmp_path / "link.txt"
    link.symlink_to(tmp_path / "made.txt")
    with atomic_write(link) as f:
        f.write("made")
    assert link.is_symlink() and (tmp_path / "made.txt").read_text() == "made"


def test_fifo_is_written_once_and_stays_a_fifo(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    result = read_fifo_in_background(fifo)
    payload = b"x" * 300_000  # more than a pipe holds at once
    with atomic_write(fifo, binary=True) as f:
        f.write(payload[:1000])
        f.write(payload[1000:])
    assert result() == payload
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_fifo_gets_nothing_when_the_output_fails(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)
    try:
        with pytest.raises(RuntimeError), atomic_write(fifo) as f:
            f.write("half a report")
            raise RuntimeError("boom")
        assert os.read(reader, 100) == b""  # no writer ever opened it
    finally:
        os.close(reader)
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)




def test_character_device_is_written_in_place(tmp_path):
    device = make_null_device(tmp_path)
    with atomic_write(device) as f:
        f.write("discarded")
    assert stat.S_ISCHR(os.stat(device).st_mode)
    assert os.listdir(tmp_path) == ["null"]


def test_directory_is_refused(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    with pytest.raises(IsADirectoryError), atomic_write(folder) as f:
        f.write("never")
    assert os.listdir(folder) == []
    link = tmp_path / "link"
    link.symlink_to(folder)
    with pytest.raises(IsADirectoryError), atomic_write(link) as f:
        f.write("never")
    assert link.is_symlink() and os.listdir(folder) == []
