"""Shared helpers of the data scripts: where things live, checksums, and the private
Python dependencies (installed by the scripts themselves, never by hand).

Standard library only, so `fetch.py --self-test` runs on a bare Python.
"""

import hashlib
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
CHECKSUMS = os.path.join(HERE, "checksums.txt")

# Pinned so that a prepared set is reproducible byte for byte. numpy+scipy read both
# NetCDF files (they are netCDF-3 classic, which scipy.io reads without HDF5);
# Pillow draws the contact sheet.
PYDEPS = ["numpy==2.2.6", "scipy==1.15.3", "pillow==11.2.1"]


class DataError(Exception):
    """A failure the user can act on; printed without a traceback."""


def sha256_of(path, chunk=1 << 20):
    """Hex sha256 of a file, streamed (the GLOBE wheel is 67 MB)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while True:
            block = f.read(chunk)
            if not block:
                return h.hexdigest()
            h.update(block)


def read_checksums(path=CHECKSUMS):
    """{file name: sha256} from a `sha256sum`-style file (`HEX  NAME`, # comments)."""
    sums = {}
    if not os.path.exists(path):
        return sums
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split()
            if len(parts) != 2 or len(parts[0]) != 64:
                raise DataError(f"{path}:{number}: expected 'SHA256  FILE', got {line!r}")
            sums[parts[1]] = parts[0].lower()
    return sums


def append_checksum(name, digest, path=CHECKSUMS):
    """Records a first download's checksum (trust on first use, then pinned in git)."""
    with open(path, "a", encoding="utf-8") as f:
        f.write(f"{digest}  {name}\n")


def verify(path, expected):
    """Raises a DataError naming the file, the expected and the actual sha256."""
    actual = sha256_of(path)
    if actual != expected:
        raise DataError(
            f"checksum mismatch for {os.path.basename(path)}:\n  expected {expected}\n  actual   {actual}\n"
            "The download is corrupt or the registry serves a different file; it was not used."
        )
    return actual


def run(cmd, cwd=None):
    """Runs a command, echoing it; a failure becomes a DataError with the command line."""
    print("+ " + " ".join(cmd), flush=True)
    result = subprocess.run(cmd, cwd=cwd)
    if result.returncode != 0:
        raise DataError(f"command failed (exit {result.returncode}): {' '.join(cmd)}")


def ensure_pydeps(data_dir):
    """Installs numpy/scipy/Pillow into DATA/pydeps (once per Python version and pin set)
    and puts them on sys.path, so the scripts need nothing installed system-wide."""
    target = os.path.join(data_dir, "pydeps")
    tag = f"py{sys.version_info.major}.{sys.version_info.minor} " + " ".join(PYDEPS)
    marker = os.path.join(target, ".installed")
    current = open(marker, encoding="utf-8").read() if os.path.exists(marker) else ""
    if current != tag:
        # A half-finished or outdated install is replaced whole rather than patched.
        if os.path.isdir(target):
            import shutil

            shutil.rmtree(target)
        run([sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
             "--target", target] + PYDEPS)
        with open(marker, "w", encoding="utf-8") as f:
            f.write(tag)
    if target not in sys.path:
        sys.path.insert(0, target)


def main_guard(fn):
    """Runs `fn()`, turning DataError into a one-line message and exit status 1."""
    try:
        fn()
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        sys.exit(1)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        sys.exit(130)
