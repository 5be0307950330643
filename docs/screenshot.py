"""Screenshot of a recording in the headless Rerun viewer, as in
docs/book/src/figures/vibrated_bed.png.

    python docs/screenshot.py bed.rrd docs/book/src/figures/vibrated_bed.png [--wait 12]

Starts `rerun --headless` on the file (it opens on the last frame, following the data), waits
`--wait` seconds so that the file is loaded and the viewer's start-up notices are gone, saves a screenshot through the viewer's gRPC API and stops the viewer. Needs
rerun-sdk (examples/requirements.txt) and a Vulkan driver (Mesa's lavapipe will do:
`apt-get install mesa-vulkan-drivers`).
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time

import rerun.experimental as rrx


def main():
    p = argparse.ArgumentParser()
    p.add_argument("rrd")
    p.add_argument("png")
    p.add_argument("--wait", type=float, default=12.0)
    p.add_argument("--port", type=int, default=9877)
    p.add_argument("--size", default="1280x800")
    a = p.parse_args()
    rerun = shutil.which("rerun", path=os.path.dirname(sys.executable)) or "rerun"
    viewer = subprocess.Popen(
        [rerun, "--headless", "--renderer", "vulkan", "--bind", "127.0.0.1",
         "--port", str(a.port), "--window-size", a.size, a.rrd],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )
    try:
        time.sleep(a.wait)
        client = rrx.ViewerClient(f"rerun+http://127.0.0.1:{a.port}/proxy")
        # The viewer writes the file: give it an absolute path.
        out = os.path.abspath(a.png)
        client.save_screenshot(out)
        for _ in range(100):
            if os.path.exists(out) and os.path.getsize(out) > 0:
                break
            time.sleep(0.1)
        print(f"wrote {out}")
    finally:
        viewer.terminate()
        viewer.wait(timeout=10)


if __name__ == "__main__":
    main()
