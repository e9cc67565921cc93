"""Headless Chromium driven over the Chrome DevTools Protocol on ``--remote-debugging-pipe``.

JSON messages, each ended by a NUL byte, are read by the browser from fd 3 and
written to fd 4, so nothing beyond the browser itself is needed or downloaded.
"""

from __future__ import annotations

import fcntl
import json
import os
import select
import shutil
import subprocess
import time
from pathlib import Path

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--remote-debugging-pipe"]


def _above_4(fd: int) -> int:
    """``fd`` moved to a number above 4 (close-on-exec), so the child's dup2 onto 3 and 4 never
    meets itself: dup2 of an fd onto its own number would keep it close-on-exec."""
    moved = fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 5)
    os.close(fd)
    return moved


class DevTools:
    """A Chromium process and its DevTools pipe: commands out, replies and events in."""

    def __init__(self, profile: Path, flags: list[str] = FLAGS):
        to_browser_read, self._write = map(_above_4, os.pipe())
        self._read, from_browser_write = map(_above_4, os.pipe())

        def wire_pipe_to_fds_3_and_4():
            os.dup2(to_browser_read, 3)
            os.dup2(from_browser_write, 4)

        self.process = subprocess.Popen(
            [CHROMIUM, *flags, f"--user-data-dir={profile}", "about:blank"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            close_fds=False, preexec_fn=wire_pipe_to_fds_3_and_4,
        )
        os.close(to_browser_read)
        os.close(from_browser_write)
        self._buffer = b""
        self._next_id = 0
        self.events: list[dict] = []

    def _receive(self, deadline: float) -> dict:
        while b"\0" not in self._buffer:
            ready, _, _ = select.select([self._read], [], [], max(0.0, deadline - time.monotonic()))
            chunk = os.read(self._read, 1 << 20) if ready else b""
            if not chunk:
                raise TimeoutError("no answer from chromium")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, params: dict | None = None, session: str | None = None, timeout: float = 30.0) -> dict:
        """Send a command and return its result; events arriving meanwhile are kept in ``events``."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self._write, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            reply = self._receive(deadline)
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)

    def wait_for(self, event: str, timeout: float = 30.0) -> dict:
        deadline = time.monotonic() + timeout
        while not any(e.get("method") == event for e in self.events):
            self.events.append(self._receive(deadline))
        return next(e for e in self.events if e.get("method") == event)

    def close(self) -> None:
        try:
            self.call("Browser.close", timeout=5)
        except (TimeoutError, RuntimeError, OSError):
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        os.close(self._read)
        os.close(self._write)


#: Flags for WebGL without a GPU: ANGLE on SwiftShader, the software Vulkan/GL Chromium ships.
WEBGL_FLAGS = [flag for flag in FLAGS if flag != "--disable-gpu"] + [
    "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"]


def open_page(browser: DevTools, url: str, width: int, height: int, timeout: float = 60.0) -> str:
    """A new tab of ``browser`` at ``url``, ``width`` x ``height`` CSS pixels at scale 1, loaded: its session id."""
    target = browser.call("Target.createTarget", {"url": "about:blank"})["targetId"]
    session = browser.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
    for domain in ("Page", "Runtime", "Log", "Network"):
        browser.call(f"{domain}.enable", session=session)
    browser.call("Emulation.setDeviceMetricsOverride",
                 {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False}, session=session)
    browser.events.clear()  # an earlier tab's load event must not count for this one
    browser.call("Page.navigate", {"url": url}, session=session)
    browser.wait_for("Page.loadEventFired", timeout=timeout)
    return session


def evaluate(browser: DevTools, session: str, expression: str, timeout: float = 60.0):
    """The value of a JavaScript expression in the page (promises awaited)."""
    reply = browser.call("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True},
                         session=session, timeout=timeout)
    if "exceptionDetails" in reply:
        raise RuntimeError(reply["exceptionDetails"].get("exception", {}).get("description", reply["exceptionDetails"]))
    return reply["result"].get("value")
