"""Headless Chromium for tests: open a page, take screenshots, read their pixels.

Chromium is started with a new empty profile, no network of its own (no
background connections, no updates, no sync), software WebGL, and the
DevTools protocol on a port it chooses; this module speaks that protocol
over a websocket (the ``websockets`` package, which the view's viser brings)
-- the page is opened, waited for and photographed with ``Page.*`` and
``Runtime.evaluate`` commands.  Every wait is bounded.

:func:`find_chromium` says where Chromium is, or why a test must skip.
"""

from __future__ import annotations

import base64
import io
import itertools
import json
import os
import pathlib
import re
import shutil
import subprocess
import tempfile
import threading
import time
from collections.abc import Callable

import numpy as np

CHROMIUM_NAMES = ('chromium', 'chromium-browser', 'google-chrome')
CHROMIUM_ENV = 'PAN_TILT_SIM_CHROMIUM'  # a Chromium elsewhere than on PATH
NOT_INSTALLED = ('Chromium is not installed (Debian: apt-get install chromium; .ci/run '
                 'installs it), so the view is not rendered in a browser')
FLAGS = ('--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync',
         # WebGL without a GPU: SwiftShader, which Chromium no longer picks by itself.
         '--enable-unsafe-swiftshader', '--use-angle=swiftshader',
         '--remote-debugging-port=0', '--remote-debugging-address=127.0.0.1')
DEVTOOLS_LINE = re.compile(r'DevTools listening on (ws://\S+)')
START_BUDGET_S = 30.0
COMMAND_BUDGET_S = 60.0  # a screenshot of software-rendered WebGL on a busy machine
POLL_S = 0.1
WIDTH, HEIGHT = 800, 600


class PageError(AssertionError):
    """A DevTools command failed (the page may be between two documents)."""


def find_chromium() -> str | None:
    """Return the Chromium executable to use, or None where there is none."""
    override = os.environ.get(CHROMIUM_ENV)
    if override:
        return override if os.access(override, os.X_OK) else None
    return next((found for name in CHROMIUM_NAMES if (found := shutil.which(name))), None)


class Browser:
    """One headless Chromium and one page in it."""

    def __init__(self, executable: str) -> None:
        from websockets.sync.client import connect  # the view's dependency brings it

        self._profile = tempfile.TemporaryDirectory(prefix='pan_tilt_sim_chromium_')
        self._process = subprocess.Popen(
            [executable, *FLAGS, f'--user-data-dir={self._profile.name}',
             f'--window-size={WIDTH},{HEIGHT}', 'about:blank'],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
            text=True)
        self._lines: list[str] = []
        self._reader = threading.Thread(target=self._read_stderr, daemon=True)
        self._reader.start()
        address = self._wait(lambda: next((m.group(1) for line in list(self._lines)
                                           if (m := DEVTOOLS_LINE.search(line))), None),
                             START_BUDGET_S, 'Chromium did not open its DevTools port')
        self._socket = connect(address, max_size=None, open_timeout=START_BUDGET_S)
        self._ids = itertools.count(1)
        target = self.command('Target.createTarget', url='about:blank')['targetId']
        self._session = self.command('Target.attachToTarget', targetId=target,
                                     flatten=True)['sessionId']
        self.command('Emulation.setDeviceMetricsOverride', session=True, width=WIDTH,
                     height=HEIGHT, deviceScaleFactor=1, mobile=False)

    def _read_stderr(self) -> None:
        for line in self._process.stderr:
            self._lines.append(line)

    @property
    def log(self) -> str:
        """What Chromium printed so far."""
        return ''.join(self._lines)

    def _wait(self, found: Callable[[], object], budget_s: float, failure: str):
        def found_or_ended():
            if self._process.poll() is not None:
                raise AssertionError(f'{failure}: Chromium ended; it said:\n{self.log[-3000:]}')
            return found()
        try:
            return wait_until(found_or_ended, budget_s, failure)
        except AssertionError as err:
            raise AssertionError(f'{err}; Chromium said:\n{self.log[-3000:]}') from None

    def command(self, method: str, *, session: bool = False, **params) -> dict:
        """Send one DevTools command and return its result (events in between are skipped)."""
        ident = next(self._ids)
        message = {'id': ident, 'method': method, 'params': params}
        if session:
            message['sessionId'] = self._session
        self._socket.send(json.dumps(message))
        deadline = time.monotonic() + COMMAND_BUDGET_S
        while True:
            reply = json.loads(self._socket.recv(timeout=max(deadline - time.monotonic(), 0.0)))
            if reply.get('id') == ident:
                if 'error' in reply:
                    raise PageError(f'{method}: {reply["error"]}')
                return reply['result']

    def open(self, url: str) -> None:
        """Load ``url`` in the page."""
        self.command('Page.enable', session=True)
        self.command('Page.navigate', session=True, url=url)

    def evaluate(self, expression: str):
        """Return the value of a JavaScript expression in the page."""
        result = self.command('Runtime.evaluate', session=True, expression=expression,
                              returnByValue=True)
        return result['result'].get('value')

    def screenshot(self) -> np.ndarray:
        """Return the page as it is now: height x width x 3 uint8 pixels."""
        from PIL import Image  # matplotlib's dependency

        data = self.command('Page.captureScreenshot', session=True, format='png')['data']
        with Image.open(io.BytesIO(base64.b64decode(data))) as image:
            return np.asarray(image.convert('RGB'))

    def screenshot_when(self, condition: Callable[[np.ndarray], bool], budget_s: float,
                        failure: str) -> np.ndarray:
        """Take screenshots until one meets ``condition`` (bounded); return it."""
        last: list[np.ndarray] = []

        def attempt():
            try:
                pixels = self.screenshot()
            except PageError:  # mid-navigation: "Not attached to an active page"
                return None
            last[:] = [pixels]
            return pixels if condition(pixels) else None
        try:
            return self._wait(attempt, budget_s, failure)
        except AssertionError:
            if last:
                save(last[0], pathlib.Path(tempfile.gettempdir()) / 'pan_tilt_sim_view.png')
            raise

    def close(self) -> None:
        """End Chromium and remove its profile."""
        try:
            self._socket.close()
        finally:
            self._process.terminate()
            try:
                self._process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
            self._profile.cleanup()


def wait_until(found: Callable[[], object], budget_s: float, failure: str):
    """Return ``found()``'s first value that is not None or False (AssertionError: too late)."""
    deadline = time.monotonic() + budget_s
    while (value := found()) is None or value is False:
        if time.monotonic() > deadline:
            raise AssertionError(f'{failure} within {budget_s:g} s')
        time.sleep(POLL_S)
    return value


def save(pixels: np.ndarray, path: pathlib.Path) -> pathlib.Path:
    """Write pixels to a PNG file (to look at a failed test's screenshot)."""
    from PIL import Image

    Image.fromarray(pixels).save(path)
    return path
