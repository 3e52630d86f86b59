"""``Plotter.show(jupyter_backend='server')`` tested for real: a Jupyter kernel (jupyter_client, as a notebook
front end runs it) draws the ray-cast sphere and shows it with trame's server-side rendering
(splinevis.gl.trame_view); headless Chromium (Debian's ``chromium``, which tools/dev.sh installs) loads the page
of the frame the cell displayed, driven through the Chrome DevTools protocol until the streamed picture has
arrived at the view's size; the screenshot's pixels must show the magenta sphere where an offscreen render of the same
scene at the view's size, in the kernel, shows it (a vtk.js page would show the proxy box, a loading page none)."""

from __future__ import annotations

import asyncio
import base64
import contextlib
import html
import io
import json
import os
import re
import signal
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.gl

TESTS = Path(__file__).resolve().parent
WIDTH, HEIGHT = 320, 240
DEADLINE = 30.0  # seconds for the page to show the streamed picture (measured 4-6 s with chromium's start, loaded machine)

CELL = f"""
import sys
sys.path.insert(0, {str(TESTS)!r})
import numpy as np
import splinevis
from _sphere_scene import CAMERA, sphere
def scene(pl):
    pl.set_background("black")
    pl.add_spline(model, lights=0, color=(1.0, 0.0, 1.0))
    pl.camera_position = CAMERA
    return pl
model = sphere()
pl = scene(splinevis.Plotter(notebook=True, window_size=({WIDTH}, {HEIGHT})))
pl.show(jupyter_backend="server")
"""

# The same scene rendered offscreen at the size of the page's view, by a plotter trame does not drive (trame keeps
# the shown plotter's window at the size the page last asked for).
REFERENCE = """
ref = scene(splinevis.Plotter(off_screen=True, window_size=({w}, {h})))
np.save({path!r}, ref.screenshot())
ref.close()
"""

# What the page shows: the view's <img> (the server's last picture, a blob) and the menu card over it.
PAGE_STATE = """JSON.stringify({
  imgs: [...document.querySelectorAll('img')].filter(e => e.src.startsWith('blob:')).map(e => {
    const r = e.getBoundingClientRect();
    return {w: e.naturalWidth, h: e.naturalHeight, cw: e.clientWidth, ch: e.clientHeight, done: e.complete,
            x: r.left, y: r.top}; }),
  menus: [...document.querySelectorAll('.v-card')].map(e => {
    const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; })
})"""


def _magenta(img):
    """Pixels of the sphere: drawn unlit in (255, 0, 255) on black; JPEG streaming moves channels by tens at most."""
    img = img.astype(int)
    return (img[..., 0] > 150) & (img[..., 2] > 150) & (img[..., 1] < 100)


def _run_cell(kc, code):
    outputs = []
    reply = kc.execute_interactive(code, output_hook=outputs.append, timeout=120)
    errors = [m["content"] for m in outputs if m["msg_type"] == "error"]
    assert reply["content"]["status"] == "ok", errors
    return outputs


async def _browse(url, profile, shot_path):
    """Chromium shows ``url`` in a WIDTH x HEIGHT viewport; returns (screenshot RGB, page state) once the view's
    picture has the view's size, or fails with what the page showed by the deadline."""
    import aiohttp  # trame's web server library (wslink), here a client of the DevTools websocket

    port_file = profile / "DevToolsActivePort"  # chromium writes its DevTools port there
    port_file.unlink(missing_ok=True)
    proc = subprocess.Popen(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                             "--no-first-run", "--remote-debugging-port=0", "--remote-debugging-address=127.0.0.1",
                             f"--user-data-dir={profile}", "about:blank"],
                            stdout=subprocess.DEVNULL, stderr=open(profile / "chromium.log", "w"),
                            start_new_session=True)  # its own process group: its helpers end with it
    start = time.monotonic()
    try:
        while not (port_file.exists() and len(port_file.read_text().split()) >= 2):
            if proc.poll() is not None or time.monotonic() - start > DEADLINE:
                pytest.fail(f"chromium did not open its DevTools port: {(profile / 'chromium.log').read_text()[-1500:]}")
            await asyncio.sleep(0.05)
        port = port_file.read_text().split()[0]
        async with aiohttp.ClientSession() as session:
            async with session.get(f"http://127.0.0.1:{port}/json/list") as resp:
                target = next(t for t in await resp.json() if t["type"] == "page")
            async with session.ws_connect(target["webSocketDebuggerUrl"], max_msg_size=0) as ws:
                ids = iter(range(1, 10**6))

                async def call(method, **params):
                    n = next(ids)
                    await ws.send_json({"id": n, "method": method, "params": params})
                    while True:
                        msg = await asyncio.wait_for(ws.receive_json(), DEADLINE)
                        if msg.get("id") == n:
                            assert "error" not in msg, msg
                            return msg["result"]

                await call("Emulation.setDeviceMetricsOverride", width=WIDTH, height=HEIGHT, deviceScaleFactor=1,
                           mobile=False)
                await call("Page.navigate", url=url)
                state, ready_since = {}, None
                while time.monotonic() - start < DEADLINE:
                    res = await call("Runtime.evaluate", expression=PAGE_STATE, returnByValue=True)
                    state = json.loads(res["result"]["value"])
                    ready = any(i["done"] and i["w"] == i["cw"] > 0 and i["h"] == i["ch"] > 0 for i in state["imgs"])
                    ready_since = (ready_since or time.monotonic()) if ready else None
                    if ready_since and time.monotonic() - ready_since > 0.5:  # the still picture after any resize
                        break
                    await asyncio.sleep(0.1)
                shot = base64.b64decode((await call("Page.captureScreenshot", format="png"))["data"])
        shot_path.write_bytes(shot)
        if not ready_since:
            pytest.fail(f"no picture of the view's size within {DEADLINE:.0f} s; the page showed {state} "
                        f"(screenshot: {shot_path})")
        from PIL import Image

        return np.asarray(Image.open(io.BytesIO(shot)).convert("RGB")), state
    finally:
        for sig, wait in ((signal.SIGTERM, 5), (signal.SIGKILL, None)):
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, sig)
            try:
                proc.wait(wait)
                break
            except subprocess.TimeoutExpired:
                continue


def test_server_backend_streams_the_spline_to_chromium(tmp_path):
    if shutil.which("chromium") is None:
        pytest.fail("chromium is missing: install Debian's package (apt-get install chromium), as "
                    "`bash tools/dev.sh setup` does")
    from jupyter_client.manager import start_new_kernel

    km, kc = start_new_kernel(kernel_name="python3", cwd=str(tmp_path))
    try:
        outputs = _run_cell(kc, CELL)
        frames = [m["content"]["data"]["text/html"] for m in outputs
                  if m["msg_type"] == "display_data" and "text/html" in m["content"]["data"]]
        assert frames, f"the cell displayed no frame: {outputs}"
        url = html.unescape(re.search(r'src="([^"]+)"', frames[-1]).group(1))
        assert url.startswith("http://localhost:"), url
        profile = tmp_path / "chromium"
        profile.mkdir()
        shot, state = asyncio.run(_browse(url, profile, tmp_path / "page.png"))
        view = next(i for i in state["imgs"] if i["done"] and i["w"] == i["cw"])
        _run_cell(kc, REFERENCE.format(w=view["w"], h=view["h"], path=str(tmp_path / "kernel.npy")))
    finally:
        kc.stop_channels()
        km.shutdown_kernel(now=True)
    reference = np.load(tmp_path / "kernel.npy")
    x, y = round(view["x"]), round(view["y"])
    page = shot[y:y + view["h"], x:x + view["w"]]
    assert page.shape == reference.shape, (page.shape, reference.shape)
    keep = np.ones(page.shape[:2], bool)  # the menu card covers part of the view: compare the rest
    for left, top, right, bottom in state["menus"]:
        keep[max(0, int(top) - y - 1):max(0, int(np.ceil(bottom)) - y + 1),
             max(0, int(left) - x - 1):max(0, int(np.ceil(right)) - x + 1)] = False
    got, want = _magenta(page) & keep, _magenta(reference) & keep
    # The sphere covers a disc of radius r ~ 0.37 * HEIGHT pixels (radius 0.7 at distance 3.6 under a 30 degree
    # view angle). JPEG coding of the stream blurs its edge by about a pixel, so at most ~2 pixels along its
    # perimeter 2 pi r differ: 4 / r < 5 % of the disc. The proxy box (what vtk.js would draw) would differ by
    # far more (the silhouette of a box around the sphere, seen along (2.6, -1.9, 1.7), has over twice the disc's
    # area); a blank page by 100 %.
    assert want.sum() > 0.2 * keep.sum()  # the kernel's render shows the sphere
    union = (got | want).sum()
    assert (got & want).sum() / union > 0.9, f"the page's sphere differs (screenshot: {tmp_path / 'page.png'})"


@pytest.mark.parametrize("backend", ["client", "html", "trame", "TRAME"])
def test_browser_side_backends_are_refused(backend):
    import splinevis

    pl = splinevis.Plotter(notebook=True, off_screen=True, window_size=(32, 24))
    with pytest.raises(ValueError, match="vtk.js.*, which drops splinevis's GLSL.*'static'.*'server'"):
        pl.show(jupyter_backend=backend)
    pl.close()


def test_default_backend_in_a_kernel_is_server():
    """In a running event loop (a kernel's) with trame-pyvista installed, ``show()`` with no backend serves the
    picture (an IFrame of the trame page), not PyVista's default 'trame' page with its switch to vtk.js."""
    import splinevis
    from splinevis.gl import trame_view

    async def cell():
        pl = splinevis.Plotter(notebook=True, off_screen=True, window_size=(64, 48))
        frame = pl.show(return_viewer=True)
        server = trame_view.launch()[0]
        await server.ready
        await server.stop()
        pl.close()
        return frame

    frame = asyncio.run(cell())
    assert type(frame).__name__ == "IFrame" and "/index.html?ui=" in frame.src, frame
