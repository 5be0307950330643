"""Executes a notebook end to end, as CI does with examples/gamma_sweep.ipynb: every cell in a
fresh kernel of this Python (the one vibrobed is installed in), in the notebook's folder; a cell
that raises fails the run. The executed notebook (outputs included) is written to --out.

    python examples/run_notebook.py examples/gamma_sweep.ipynb --out run.ipynb

Environment for the notebook: VIBROBED_SWEEP (the sweep's folder, default gamma_sweep beside
it), VIBROBED_FIGURES (where its figures go, default figures beside it).
"""

import argparse
import os
import pathlib
import sys
import time

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebook", type=pathlib.Path)
    ap.add_argument("--out", type=pathlib.Path, required=True, help="the executed notebook")
    ap.add_argument("--timeout", type=int, default=600, help="seconds per cell")
    ap.add_argument("--widgets", type=int, default=0,
                    help="fail unless the outputs hold at least this many widgets (viewers)")
    ap.add_argument("--images", type=int, default=0,
                    help="fail unless the outputs hold at least this many images (figures)")
    args = ap.parse_args()
    # The kernel is this Python's (ipykernel's `python3` starts `python` from the PATH).
    os.environ["PATH"] = os.path.dirname(sys.executable) + os.pathsep + os.environ["PATH"]
    nb = nbformat.read(args.notebook, as_version=4)
    client = NotebookClient(
        nb,
        timeout=args.timeout,
        kernel_name="python3",
        resources={"metadata": {"path": str(args.notebook.resolve().parent)}},
    )
    start = time.perf_counter()
    try:
        client.execute()
    except CellExecutionError as e:
        nbformat.write(nb, args.out)
        print(f"{args.notebook}: a cell failed (the notebook so far: {args.out})\n{e}",
              file=sys.stderr)
        sys.exit(1)
    nbformat.write(nb, args.out)
    cells = sum(c.cell_type == "code" for c in nb.cells)
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    widgets = sum("application/vnd.jupyter.widget-view+json" in o.get("data", {}) for o in outputs)
    images = sum("image/png" in o.get("data", {}) for o in outputs)
    print(f"{args.notebook}: {cells} code cells executed in {time.perf_counter() - start:.0f} s; "
          f"outputs: {widgets} widgets, {images} images")
    if widgets < args.widgets or images < args.images:
        sys.exit(f"expected at least {args.widgets} widgets and {args.images} images")


if __name__ == "__main__":
    main()
