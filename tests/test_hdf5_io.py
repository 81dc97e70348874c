#!/usr/bin/env python3
"""Check casca's HDF5 output (src/output/hdf5_io.f90) from the outside, with h5py.

Usage:
    python3 tests/test_hdf5_io.py TEST_HDF5_IO [OUTDIR]

TEST_HDF5_IO is the test_hdf5_io executable built from tests/test_hdf5_io.f90, or the folder
holding it. It is run with OUTDIR as its working directory (created if missing; a fresh
temporary folder if omitted), where it leaves the files read back here:
    hdf5_io_table.h5    1000 rows: row i (1-based), column j = i*10 + j + 1/3
    hdf5_io_restart.h5  610 rows: rows 1..600 as above, rows i = 601..610 = -(i*10 + j) - 1/3
    hdf5_io_ckpt.h5     the last checkpoint the test wrote (ndof = 0, no ints, t = 0.1*3)
Values are compared bit for bit. Exits non-zero on any failure.
"""
import os
import subprocess
import sys
import tempfile

import numpy as np
import h5py
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from casca_testlib import Checks  # noqa: E402

# Must match tests/test_hdf5_io.f90.
NCOL, NROWS, NKEEP, NMORE = 5, 1000, 600, 10
COLUMNS = ["time", "energy_kin", "energy_pot", "u_tip", "n_contact"]
FILES = ["hdf5_io_table.h5", "hdf5_io_restart.h5", "hdf5_io_ckpt.h5", "hdf5_io_not_h5.txt"]

CK = Checks()


def check(ok, what):
    CK.record(what, ok)
    return ok


def expected(rows, sign=1.0):
    """Rows `rows` (1-based) of the table: i*10 + j + 1/3, times sign, exactly as Fortran."""
    i = np.asarray(rows, dtype=np.int64)[:, None]
    j = np.arange(1, NCOL + 1, dtype=np.int64)[None, :]
    return sign * ((i * 10 + j).astype(np.float64) + 1.0 / 3.0)


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def check_table(path, nrows, want):
    name = os.path.basename(path)
    try:
        f = h5py.File(path, "r")
    except Exception as exc:  # any reader failure is a test failure, not a crash
        check(False, f"{name}: h5py opens it ({type(exc).__name__}: {exc})")
        return
    with f:
        if not check("history" in f, f"{name}: has dataset /history"):
            return
        d = f["history"]
        check(d.shape == (nrows, NCOL), f"{name}: shape (rows, ncol) = {(nrows, NCOL)} "
              f"(got {d.shape})")
        check(d.dtype == np.float64, f"{name}: float64 (got {d.dtype})")
        check(d.chunks is not None and d.maxshape == (None, NCOL),
              f"{name}: chunked, maxshape (None, {NCOL}) (got {d.maxshape})")
        raw = d.attrs.get("columns")
        check(raw is not None and np.asarray(raw).dtype.kind == "S",
              f"{name}: attribute 'columns' is a fixed-length string array "
              f"(got {None if raw is None else np.asarray(raw).dtype})")
        names = [] if raw is None else [c.decode() if isinstance(c, bytes) else str(c)
                                        for c in raw]
        check(names == COLUMNS, f"{name}: column names {COLUMNS} (got {names})")
        if d.shape == (nrows, NCOL):
            got = d[...]
            check(same_bits(got, want), f"{name}: all {got.size} values bitwise exact")


def check_checkpoint(path):
    name = os.path.basename(path)
    try:
        f = h5py.File(path, "r")
    except Exception as exc:
        check(False, f"{name}: h5py opens it ({type(exc).__name__}: {exc})")
        return
    with f:
        keys = sorted(f.keys())
        check(keys == sorted(["t", "step", "ndof", "q", "qd", "qdd", "ints", "reals"]),
              f"{name}: datasets t, step, ndof, q, qd, qdd, ints, reals (got {keys})")
        if "t" in f and "ndof" in f and "q" in f:
            check(same_bits(f["t"][()], 0.1 * 3.0) and f["ndof"][()] == 0
                  and f["q"].shape == (0,), f"{name}: t = 0.1*3, ndof = 0, q empty")


def main():
    if len(sys.argv) not in (2, 3):
        print(__doc__)
        return 2
    exe = os.path.abspath(sys.argv[1])
    if os.path.isdir(exe):
        exe = os.path.join(exe, "test_hdf5_io")
    outdir = os.path.abspath(sys.argv[2]) if len(sys.argv) == 3 else tempfile.mkdtemp(
        prefix="casca_hdf5_")
    os.makedirs(outdir, exist_ok=True)
    for f in FILES:
        if os.path.exists(os.path.join(outdir, f)):
            os.remove(os.path.join(outdir, f))

    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    run = subprocess.run([exe], cwd=outdir, env=env, capture_output=True, text=True,
                         timeout=60)
    sys.stdout.write(run.stdout)
    sys.stderr.write(run.stderr)
    if not check(run.returncode == 0, f"{os.path.basename(exe)} exits 0 (got {run.returncode})"):
        print(f"{CK.passed} passed, {CK.failed} failed")
        return 1

    leftovers = [f for f in os.listdir(outdir) if f.endswith(".part")]
    check(not leftovers, f"no .part files left behind (found {leftovers})")

    check_table(os.path.join(outdir, "hdf5_io_table.h5"), NROWS,
                expected(range(1, NROWS + 1)))
    check_table(os.path.join(outdir, "hdf5_io_restart.h5"), NKEEP + NMORE,
                np.vstack([expected(range(1, NKEEP + 1)),
                           expected(range(NKEEP + 1, NKEEP + NMORE + 1), -1.0)]))
    check_checkpoint(os.path.join(outdir, "hdf5_io_ckpt.h5"))

    print(f"{CK.passed} passed, {CK.failed} failed")
    return 0 if CK.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
