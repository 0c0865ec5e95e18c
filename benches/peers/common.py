"""Shared pieces of the peer benchmarks: the bunny mesh as glint places it,
and glint's camera.

Everything here mirrors glint's own definitions:
  * placement (src/scene, mesh objects): p' = Rz * Ry * Rx * (p * scale) + translate
  * camera (src/camera.rs): w = normalize(eye - lookat),
    u = normalize(cross(normalize(up), w)), v = cross(w, u),
    half_height = tan(fov / 2) (fov is VERTICAL, edge to edge),
    pixel_size = 2 * half_height / height, left = -pixel_size * width / 2,
    top = half_height; the ray through column i, row j (row 0 at the top) at
    offset (dx, dy) has direction
    normalize((left + (i + dx) * pixel_size) * u + (top - (j + dy) * pixel_size) * v - w)
    and origin eye.
"""

import math
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
BUNNY_OBJ = os.path.join(REPO, "assets", "bunny.obj")

# scenes/bunny.toml
EYE = (0.0, 0.55, 1.9)
LOOKAT = (0.0, 0.45, 0.0)
UP = (0.0, 1.0, 0.0)
FOV_DEG = 40.0
WIDTH = 1024
HEIGHT = 768
BUNNY_SCALE = 0.1
LIGHT = (-2.0, 4.0, 4.0)

# Camera (eye, lookat) of the bunny-on-floor scene: "fill" is bunny_floor.toml
# (the bunny fills the frame), "small" bunny_floor_small.toml (the bunny a
# quarter of the frame's height, most rays on the floor).
FRAMINGS = {
    "fill": (EYE, LOOKAT),
    "small": ((0.0, 1.6, 5.5), (0.0, 0.3, 0.0)),
}


def load_obj(path):
    """Positions (n, 3) float64 and triangles (m, 3) int64, zero-based.

    Reads `v` and `f` records only; a face's vertex may be written `i`,
    `i/t`, `i//n` or `i/t/n`, negative indices count from the end, and
    polygons with more than three vertices are fanned (the bunny has none).
    """
    verts = []
    faces = []
    with open(path, "r", encoding="utf-8") as fh:
        for line in fh:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                verts.append((float(parts[1]), float(parts[2]), float(parts[3])))
            elif parts[0] == "f":
                idx = []
                for tok in parts[1:]:
                    k = int(tok.split("/")[0])
                    idx.append(k - 1 if k > 0 else len(verts) + k)
                for a in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[a], idx[a + 1]))
    return np.asarray(verts, dtype=np.float64), np.asarray(faces, dtype=np.int64)


def place(verts, scale=1.0, rotate_deg=(0.0, 0.0, 0.0), translate=(0.0, 0.0, 0.0)):
    """glint's mesh placement: Rz * Ry * Rx * (p * scale) + translate."""
    ax, ay, az = (math.radians(a) for a in rotate_deg)
    rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    rz = np.array([[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]])
    m = rz @ ry @ rx
    return (verts * scale) @ m.T + np.asarray(translate, dtype=np.float64)


def placed_bunny():
    verts, faces = load_obj(BUNNY_OBJ)
    return place(verts, scale=BUNNY_SCALE), faces


def camera_basis(eye=EYE, lookat=LOOKAT, up=UP):
    eye = np.asarray(eye, dtype=np.float64)
    w = eye - np.asarray(lookat, dtype=np.float64)
    w /= np.linalg.norm(w)
    upn = np.asarray(up, dtype=np.float64)
    upn = upn / np.linalg.norm(upn)
    u = np.cross(upn, w)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    return eye, u, v, w


def primary_rays(width=WIDTH, height=HEIGHT, fov_deg=FOV_DEG, eye=EYE, lookat=LOOKAT, up=UP):
    """Origins and unit directions (width*height, 3), float64, row-major
    (row 0 at the top), one ray per pixel through the pixel centre."""
    eye, u, v, w = camera_basis(eye, lookat, up)
    half_height = math.tan(math.radians(fov_deg) * 0.5)
    pixel_size = 2.0 * half_height / height
    left = -pixel_size * width * 0.5
    top = half_height
    xs = left + (np.arange(width, dtype=np.float64) + 0.5) * pixel_size
    ys = top - (np.arange(height, dtype=np.float64) + 0.5) * pixel_size
    x = np.tile(xs, height)[:, None]
    y = np.repeat(ys, width)[:, None]
    d = x * u[None, :] + y * v[None, :] - w[None, :]
    d /= np.linalg.norm(d, axis=1)[:, None]
    o = np.broadcast_to(eye, d.shape).copy()
    return o, d
