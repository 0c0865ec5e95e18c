#!/usr/bin/env bash
# Peer benchmark: glint against Embree 4 (primary rays of the bunny) and
# Mitsuba 3 (bunny on a floor, direct light + hard shadows, 16 spp).
#
#   bash benches/peers/run.sh [threads]        # from the repository root; default 2 threads
#
# Environment:
#   GLINT   glint binary (default target/release/glint; this script never builds it)
#   PYTHON  Python interpreter with numpy, embreex, mitsuba and drjit (default:
#           a virtual environment the script creates and fills on first use,
#           in $GLINT_PEERS_VENV, default ~/.cache/glint/peers-venv; the
#           system Python is never touched)
#   REPS    glint repetitions, median taken (default 5)
#
# Prints a markdown table: workload, glint, peer, ratio (glint speed / peer
# speed: > 1 means glint is faster). Raw JSON of every run is kept in a
# temporary directory whose path is printed at the end.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/../.."   # repository root
THREADS="${1:-2}"
GLINT="${GLINT:-target/release/glint}"
VENV="${GLINT_PEERS_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/glint/peers-venv}"
PYTHON="${PYTHON:-$VENV/bin/python}"
REPS="${REPS:-5}"
PEERS=benches/peers
OUT="$(mktemp -d /tmp/peers-run.XXXXXX)"

if ! [[ "$THREADS" =~ ^[1-9][0-9]*$ ]]; then
    echo "usage: bash benches/peers/run.sh [threads]   (threads: a positive integer)" >&2
    exit 2
fi
if [[ ! -x "$GLINT" ]]; then
    echo "glint binary not found at $GLINT (build it with cargo build --release, or set GLINT)" >&2
    exit 1
fi

# ---------------------------------------------------------------------------
# Dependencies
# ---------------------------------------------------------------------------

# Versions these scripts were written and checked against.
PIP_PACKAGES=(numpy "embreex==4.4.0.post1" "mitsuba==3.9.1" "drjit==1.5.0")

ensure_python_deps() {
    if [[ "$PYTHON" == "$VENV/bin/python" && ! -x "$PYTHON" ]]; then
        echo "creating a virtual environment for the peers in $VENV" >&2
        python3 -m venv "$VENV" >&2 || {
            echo "python3 -m venv failed (on Debian: apt-get install python3-venv)" >&2
            exit 1
        }
    fi
    if ! "$PYTHON" -c "import numpy, embreex, mitsuba, drjit" 2>/dev/null; then
        echo "installing Python packages: ${PIP_PACKAGES[*]}" >&2
        "$PYTHON" -m pip install --quiet "${PIP_PACKAGES[@]}" >&2
    fi
}

# Dr.Jit 1.5 (Mitsuba's llvm_ad_rgb) aborts compiling its render kernel with
# Debian 12's default libLLVM 15 ("Cannot select ... fminimum"); LLVM 19 works.
find_llvm19() {
    local f
    for f in /usr/lib/x86_64-linux-gnu/libLLVM-19.so /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \
             /usr/lib/llvm-19/lib/libLLVM.so; do
        [[ -e "$f" ]] && { echo "$f"; return 0; }
    done
    return 1
}

ensure_llvm() {
    [[ -n "${DRJIT_LIBLLVM_PATH:-}" ]] && return 0
    local lib
    if ! lib="$(find_llvm19)"; then
        if command -v apt-get >/dev/null && [[ "$(id -u)" == 0 ]]; then
            echo "installing libllvm19 for Mitsuba's llvm variant" >&2
            DEBIAN_FRONTEND=noninteractive apt-get install -y -q libllvm19 >&2 \
                || { apt-get update -q >&2 && DEBIAN_FRONTEND=noninteractive apt-get install -y -q libllvm19 >&2; } \
                || echo "could not install libllvm19; Mitsuba may fall back to scalar_rgb" >&2
        fi
        lib="$(find_llvm19)" || return 0
    fi
    export DRJIT_LIBLLVM_PATH="$lib"
}

# json FILE EXPR: evaluate the Python expression EXPR on the JSON object `j` in FILE.
json() {
    "$PYTHON" -c 'import json,sys; j=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$1" "$2"
}

# median of the numbers given as arguments
median() {
    "$PYTHON" -c 'import statistics,sys; print(statistics.median(float(x) for x in sys.argv[1:]))' "$@"
}

# ---------------------------------------------------------------------------
# glint: `glint bench --octree-only` times renders without work counting
# (medians of $REPS); one `glint render --stats` gives the hit count.
# Each function prints "SECONDS MRAYS_PER_S".
# ---------------------------------------------------------------------------

# Primary rays of scenes/bunny.toml, normals view, 1 sample per pixel.
glint_bunny_primary() {
    local t="$1"
    "$GLINT" render scenes/bunny.toml --view normals --samples 1 --threads "$t" --stats \
        -o "$OUT/glint-bunny.png" >"$OUT/glint-bunny-0.json"
    "$GLINT" bench scenes/bunny.toml --view normals --samples 1 --size 1024x768 \
        --octree-only --repeat "$REPS" --threads "$t" --format json >"$OUT/glint-bunny.json"
    json "$OUT/glint-bunny.json" 'str(j[0]["octree_on"]["render_s"]) + " " + str(j[0]["octree_on"]["mrays_per_s"])'
}

# benches/peers/bunny_floor.toml (FRAMING fill) or bunny_floor_small.toml
# (small): 16 samples per pixel, eye + shadow rays.
glint_bunny_floor() {
    local t="$1" framing="$2" scene="$PEERS/bunny_floor.toml"
    [[ "$framing" == small ]] && scene="$PEERS/bunny_floor_small.toml"
    "$GLINT" bench "$scene" --octree-only --repeat "$REPS" --threads "$t" \
        --format json >"$OUT/glint-floor-$framing.json"
    json "$OUT/glint-floor-$framing.json" 'str(j[0]["octree_on"]["render_s"]) + " " + str(j[0]["octree_on"]["mrays_per_s"])'
}
# <<< END OF GLINT INVOCATION >>>
# ---------------------------------------------------------------------------

ensure_python_deps
ensure_llvm

echo "threads: $THREADS   glint: $GLINT   results: $OUT" >&2

echo "glint: bunny primary rays ..." >&2
read -r G_BUNNY_S G_BUNNY_MRAYS < <(glint_bunny_primary "$THREADS")
echo "embree: bunny primary rays ..." >&2
"$PYTHON" "$PEERS/bunny_embree.py" --threads "$THREADS" --runs 5 \
    --glint-stats "$OUT/glint-bunny-0.json" >"$OUT/embree.json"

echo "glint: bunny on floor, 16 spp, bunny filling the frame ..." >&2
read -r G_FLOOR_S G_FLOOR_MRAYS < <(glint_bunny_floor "$THREADS" fill)
echo "mitsuba: bunny on floor, 16 spp, bunny filling the frame ..." >&2
"$PYTHON" "$PEERS/bunny_floor_mitsuba.py" --threads "$THREADS" --runs 3 >"$OUT/mitsuba.json"
echo "glint: bunny on floor, 16 spp, bunny small in the frame ..." >&2
read -r G_SMALL_S G_SMALL_MRAYS < <(glint_bunny_floor "$THREADS" small)
echo "mitsuba: bunny on floor, 16 spp, bunny small in the frame ..." >&2
"$PYTHON" "$PEERS/bunny_floor_mitsuba.py" --threads "$THREADS" --runs 3 --framing small \
    >"$OUT/mitsuba-small.json"
M_SMALL_S="$(json "$OUT/mitsuba-small.json" 'j["seconds"]')"

E_S="$(json "$OUT/embree.json" 'j["seconds"]')"
E_MRAYS="$(json "$OUT/embree.json" 'j["mrays_per_s"]')"
E_HITS="$(json "$OUT/embree.json" 'j["hits"]')"
E_ROBUST="$(json "$OUT/embree.json" 'j["robust"]')"
G_HITS="$(json "$OUT/glint-bunny-0.json" 'j["rays"]["primary_hits"]')"
M_S="$(json "$OUT/mitsuba.json" 'j["seconds"]')"
M_VARIANT="$(json "$OUT/mitsuba.json" 'j["variant"]')"
M_THREADS="$(json "$OUT/mitsuba.json" 'j["threads"]')"
M_WARM="$(json "$OUT/mitsuba.json" 'j["warmup_s"]')"
M_FALLBACK="$(json "$OUT/mitsuba.json" 'j.get("fallback_reason") or ""')"

"$PYTHON" - "$THREADS" "$G_BUNNY_S" "$G_BUNNY_MRAYS" "$E_S" "$E_MRAYS" \
    "$G_FLOOR_S" "$G_FLOOR_MRAYS" "$M_S" "$M_VARIANT" "$G_SMALL_S" "$G_SMALL_MRAYS" "$M_SMALL_S" <<'EOF'
import sys
t = sys.argv[1]
g_bunny_s, g_bunny_mrays, e_s, e_mrays, g_floor_s, g_floor_mrays, m_s = map(float, sys.argv[2:9])
m_variant = sys.argv[9]
g_small_s, g_small_mrays, m_small_s = map(float, sys.argv[10:13])
print()
print(f"| workload ({t} threads) | glint | peer | ratio (glint/peer speed) |")
print("|---|---|---|---|")
print(f"| bunny primary rays, 1024x768, 1 spp (Embree 4, embreex) "
      f"| {g_bunny_mrays:.2f} Mrays/s ({g_bunny_s * 1e3:.1f} ms) "
      f"| {e_mrays:.2f} Mrays/s ({e_s * 1e3:.1f} ms) | {g_bunny_mrays / e_mrays:.3f} |")
print(f"| bunny on floor, bunny fills the frame, direct + shadows, 1024x768, 16 spp (Mitsuba 3 {m_variant}) "
      f"| {g_floor_s:.3f} s ({g_floor_mrays:.2f} Mrays/s) "
      f"| {m_s:.3f} s | {m_s / g_floor_s:.3f} |")
print(f"| bunny on floor, bunny small in the frame, same settings (Mitsuba 3 {m_variant}) "
      f"| {g_small_s:.3f} s ({g_small_mrays:.2f} Mrays/s) "
      f"| {m_small_s:.3f} s | {m_small_s / g_small_s:.3f} |")
EOF
echo
echo "- primary hits: glint $G_HITS, Embree $E_HITS (difference $((E_HITS - G_HITS))); Embree robust mode: $E_ROBUST"
echo "- Mitsuba variant $M_VARIANT, $M_THREADS threads, warm-up render (JIT) ${M_WARM} s${M_FALLBACK:+; $M_FALLBACK}"
echo "- glint: median of $REPS uncounted renders (glint bench --octree-only); Embree: median of 5; Mitsuba: median of 3 after a warm-up"
echo "- Mitsuba's 16 spp are random (independent sampler), glint's a regular 4x4 grid"
echo "- raw JSON: $OUT"
