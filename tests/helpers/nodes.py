"""Special files for output tests: a FIFO read in the background, a null character device (root only)."""

from __future__ import annotations

import os
import stat
import threading

import pytest


def read_fifo_in_background(fifo):
    """Start a reader on ``fifo``; returns a function giving what it read once the writer closed."""
    received = {}

    def reader():
        with open(fifo, "rb") as f:
            received["data"] = f.read()

    thread = threading.Thread(target=reader, daemon=True)
    thread.start()

    def result():
        thread.join(timeout=30)
        return received.get("data")

    return result


def make_null_device(tmp_path):
    """A character device with /dev/null's numbers, in tmp_path (needs root)."""
    if os.geteuid() != 0:
        pytest.skip("making a device node needs root")
    device = tmp_path / "null"
    numbers = os.stat("/dev/null").st_rdev
    try:
        os.mknod(device, 0o666 | stat.S_IFCHR, numbers)
    except PermissionError:
        pytest.skip("this container may not make device nodes")
    return device
