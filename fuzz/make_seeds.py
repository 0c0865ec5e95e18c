#!/usr/bin/env python3
"""Writes the fuzz targets' seed corpora into fuzz/seeds/<target>/ from the
repository's scenes and models, plus small hand-written files that use
every keyword the readers know. PNG seeds are glint's own exports, made
with the release binary (give its path; default target/release/glint).

    python3 fuzz/make_seeds.py [path/to/glint]
"""

import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

FUZZ = pathlib.Path(__file__).resolve().parent
REPO = FUZZ.parent
SEEDS = FUZZ / "seeds"
# Kept small: libFuzzer's default -max_len is 4096 bytes, and a seed far
# longer only slows every mutation of it.
MAX_SEED = 4096
OBJ_SEPARATOR = b"\n#--mtl--\n"
RECORD_PART = b"\n#--part--\n"


def write(target, name, data):
    folder = SEEDS / target
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_bytes(data)


def head(data, limit=MAX_SEED):
    """The first lines of `data` that fit in `limit` bytes."""
    if len(data) <= limit:
        return data
    cut = data.rfind(b"\n", 0, limit)
    return data[: cut + 1 if cut > 0 else limit]


NFF_EVERY_ENTITY = b"""v
from 0 -6 2
at 0 0 0.5
up 0 0 1
angle 40
hither 0.01
resolution 64 48
b 0.1 0.2 0.3
l 4 -4 6
l -3 -2 5 0.5 0.5 0.5
f 0.9 0.2 0.2 0.7 0.3 20 0.2 0.5 1.5
s 0 0 1 1
f 0.2 0.9 0.2 0.8 0 1 0 0 1
c 2 0 0 0.5 2 0 2 0.1
c -2 0 0 -0.5 -2 0 2 0.5
p 3
-4 -4 0
4 -4 0
0 4 0
pp 3
-1 -1 2 0 0 1
1 -1 2 0 0 1
0 1 2 0 0.6 0.8
p 5
-1 -1 3
1 -1 3
0 0 3
1 1 3
-1 1 3
# a comment
"""

OBJ_EVERY_KEYWORD = b"""# every statement the reader knows
mtllib a.mtl b.mtl
o thing
g group one
s 1
v -1 0 -1
v 1 0 -1 1.0
v 1 0 1
v -1 0 1
v 0 2 0 0.5 0.5 0.5
vt 0 0
vt 1 0 0
vt 1 1
vn 0 1 0
vn 0 0.7071 0.7071
usemtl red
f 1/1/1 2/2/1 3/3/1 4/1/1
f -5//2 -4//2 -1//2
usemtl
f 1 2 5
f 2/2 3/3 5/1
s off
usemtl glass
f 3 4 \\
  5
l 1 2 3
p 4
curv 0 1 1 2
f 1 2 9
f 1 2
"""

MTL_EVERY_KEYWORD = b"""newmtl red
Ka 0.1 0.1 0.1
Kd 0.8 0.1 0.1
Ks 0.3 0.3 0.3
Ns 40
d 1
illum 2
newmtl glass
Kd 0.1 0.1 0.1
Ks 0.9 0.9 0.9
Ns 300
Ni 1.5
Tr 0.9
Tf 0.9 1 0.9
illum 7
newmtl mirror
Kd 0 0 0
Ks 1 1 1
illum 3
map_Kd wood.png
bump -bm 0.5 bump.png
Ke 1 1 1
"""

RECORD_SETTINGS = {
    "camera": {"eye": [0.0, 1.0, 4.0], "lookat": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": 40.0},
}


def scene_seeds():
    for path in sorted((REPO / "scenes").glob("*.toml")):
        write("toml_scene", path.name, head(path.read_bytes()))
    for path in sorted((REPO / "scenes" / "spd").glob("*.nff")):
        write("nff_scene", path.name, head(path.read_bytes()))
    for path in sorted((REPO / "scenes" / "spd" / "sizes").glob("*.nff")):
        write("nff_scene", path.name, head(path.read_bytes(), 1024))
    write("nff_scene", "every_entity.nff", NFF_EVERY_ENTITY)


def model_seeds():
    box = REPO / "assets" / "cornell_box"
    write(
        "obj_mtl",
        "cornell_box",
        (box / "cornell_box.obj").read_bytes() + OBJ_SEPARATOR + (box / "cornell_box.mtl").read_bytes(),
    )
    write("obj_mtl", "every_keyword", OBJ_EVERY_KEYWORD + OBJ_SEPARATOR + MTL_EVERY_KEYWORD)
    write("obj_mtl", "bunny_head", head((REPO / "assets" / "bunny.obj").read_bytes()))


def record_seeds(glint):
    with tempfile.TemporaryDirectory() as tmp:
        for scene in ["sphere.toml", "glass.toml", "quadrics.toml", "spd/tetra.nff"]:
            out = pathlib.Path(tmp) / "out.png"
            subprocess.run(
                [glint, "render", str(REPO / "scenes" / scene), "-o", str(out), "--width", "8", "--height", "6", "--samples", "1", "-q"],
                check=True,
                capture_output=True,
            )
            png = out.read_bytes()
            name = scene.replace("/", "_").rsplit(".", 1)[0]
            # Mode byte 0: the bytes are a PNG file.
            if len(png) <= 64 * 1024:
                write("png_record", f"png_{name}", b"\x00" + png)
            info = subprocess.run(
                [glint, "info", str(out), "--json"], check=True, capture_output=True
            )
            settings = json.loads(info.stdout)["settings"]
            text = (REPO / "scenes" / scene).read_bytes()
            # Mode byte 1: settings, scene path and scene text, written by glint.
            write(
                "png_record",
                f"record_{name}",
                b"\x01" + json.dumps(settings).encode() + RECORD_PART + f"scenes/{scene}".encode()
                + RECORD_PART + head(text, 2048),
            )


def main():
    glint = sys.argv[1] if len(sys.argv) > 1 else str(REPO / "target" / "release" / "glint")
    shutil.rmtree(SEEDS, ignore_errors=True)
    scene_seeds()
    model_seeds()
    record_seeds(glint)
    # The geometry target decodes structured input from any bytes: a few
    # patterns are enough to start from.
    write("geometry", "zeros", bytes(64))
    write("geometry", "ramp", bytes(range(256)))
    count = sum(1 for _ in SEEDS.rglob("*") if _.is_file())
    print(f"wrote {count} seeds under {SEEDS.relative_to(REPO)}")


if __name__ == "__main__":
    main()
