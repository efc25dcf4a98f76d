"""What the Python benchmarks share: the scenes they name, PFM reading, running candela.

Imported by bench/samplers/*.py and bench/adaptive/run.py (which put bench/ on sys.path).
"""
import re, subprocess, sys
import numpy as np

# Scene name -> candela's arguments (the built-in Cornell box has none).
SCENES = {"cornell": [], "veach-mis": ["scenes/veach-mis/scene.xml"], "caustics": ["scenes/caustics/scene.xml"]}


def read_pfm(path):
    """A PFM as float64 (h, w, c), rows top to bottom (PFM stores them bottom to top)."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3 if kind == b"PF" else 1)[::-1].astype(np.float64)


def run_candela(cmd):
    """Runs a candela command; returns (mean spp, render seconds) from its summary line: the
    render's own time, without start-up and scene loading. Exits with the command on failure."""
    r = subprocess.run(cmd, capture_output=True, text=True)
    m = re.search(r"([0-9.e+]+) spp in ([0-9.]+) s", r.stderr)
    if r.returncode != 0 or not m:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return float(m.group(1)), float(m.group(2))
