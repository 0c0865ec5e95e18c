"""Shared pieces of the Python module's tests: the repository, the `glint`
command the module is compared with, and a PNG reader (so the tests need
nothing beyond numpy and pytest)."""

import json
import os
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


def scene_path(name):
    return str(REPO / "scenes" / name)


@pytest.fixture(scope="session")
def glint_cli():
    """Runs the `glint` command built from this repository (GLINT_BIN, or
    target/release/glint) and returns its completed process."""
    binary = Path(os.environ.get("GLINT_BIN", REPO / "target" / "release" / "glint"))
    if not binary.is_file():
        pytest.fail(f"{binary} is missing: build it with `cargo build --release` "
                    "(or point GLINT_BIN at a glint binary)")

    def run(*args, check=True):
        done = subprocess.run([str(binary), *map(str, args)], cwd=REPO,
                              capture_output=True, text=False)
        if check and done.returncode != 0:
            raise AssertionError(f"glint {' '.join(map(str, args))} failed: "
                                 f"{done.stderr.decode(errors='replace')}")
        return done

    return run


def cli_json(done):
    return json.loads(done.stdout.decode())


def read_png(path):
    """The pixels of an 8-bit RGB PNG, as glint writes them, H x W x 3."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    at, idat = 8, b""
    while at < len(data):
        (length,) = struct.unpack(">I", data[at:at + 4])
        kind, body = data[at + 4:at + 8], data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color = struct.unpack(">IIBB", body[:10])
            assert (depth, color) == (8, 2), "8-bit RGB expected"
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    raw = zlib.decompress(idat)
    stride = width * 3
    rows = np.zeros((height, stride), dtype=np.int32)
    previous = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        start = y * (stride + 1)
        kind = raw[start]
        line = np.frombuffer(raw[start + 1:start + 1 + stride], dtype=np.uint8).astype(np.int32)
        out = np.zeros(stride, dtype=np.int32)
        for x in range(stride):
            left = out[x - 3] if x >= 3 else 0
            up = previous[x]
            up_left = previous[x - 3] if x >= 3 else 0
            if kind == 0:
                predictor = 0
            elif kind == 1:
                predictor = left
            elif kind == 2:
                predictor = up
            elif kind == 3:
                predictor = (left + up) // 2
            else:
                p = left + up - up_left
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - up_left)
                predictor = left if pa <= pb and pa <= pc else (up if pb <= pc else up_left)
            out[x] = (line[x] + predictor) & 0xFF
        rows[y] = out
        previous = out
    return rows.astype(np.uint8).reshape(height, width, 3)
