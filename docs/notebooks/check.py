"""Runs the notebooks of docs/notebooks/ (the heyoka one needs the peers
and is left out) and fails on the first cell that raises: their assertions
check the module against closed forms and against the Rust scenes' summaries
(out/<scene>/summary.json), which must be there (MECHLAB_CHECK_SCENES=1).

    python docs/notebooks/check.py      # after the scenes the notebooks name
"""

import os
import pathlib
import sys
import time

import nbformat
from nbclient import NotebookClient

HERE = pathlib.Path(__file__).resolve().parent


def main() -> int:
    os.environ["MECHLAB_CHECK_SCENES"] = "1"
    os.environ.setdefault("MPLBACKEND", "Agg")
    notebooks = sorted(p for p in HERE.glob("*.ipynb") if not p.name.startswith("heyoka"))
    for path in notebooks:
        start = time.perf_counter()
        notebook = nbformat.read(path, as_version=4)
        NotebookClient(notebook, timeout=900, kernel_name="python3",
                       resources={"metadata": {"path": str(HERE)}}).execute()
        print(f"{path.name}: every cell ran ({time.perf_counter() - start:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
