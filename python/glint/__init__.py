"""glint, a Whitted-style ray tracer, from Python.

Renders to NumPy and returns what the command line reports, as dicts with
the same fields: ``render(stats=True).stats`` is ``glint render --stats``,
``trace_pixel`` is ``--trace-pixel``, ``bench`` is ``glint bench --format
json``. The work runs in the same Rust library as the ``glint`` command,
with the GIL released; Ctrl+C (a notebook's "interrupt kernel") cancels a
render. docs/python.md is the guide.

>>> import glint
>>> scene = glint.load("scenes/default.toml")
>>> frame = scene.render(200, 150)
>>> frame.rgb.shape
(150, 200, 3)
"""

import json as _json
import os as _os

from . import _glint
from ._glint import Cancelled, SceneError, __version__
from ._frame import Frame
from ._sequences import Viewpoint, frame_file, render_frames, sweep
from ._sequences import as_viewpoint as _as_viewpoint
from ._sequences import camera_path as _camera_path
from ._sequences import turntable as _turntable
from ._views import Camera, Light, Lights, Material, Materials, OctreeParams

__all__ = [
    "Camera",
    "Cancelled",
    "Frame",
    "Light",
    "Lights",
    "Material",
    "Materials",
    "OctreeParams",
    "Scene",
    "SceneError",
    "Viewpoint",
    "default_scene",
    "frame_file",
    "load",
    "render_frames",
    "sweep",
]


def load(path):
    """Loads a ``.toml`` or ``.nff`` scene, or an ``.obj`` model framed on
    its own. Raises :class:`SceneError` (with ``path``, ``line``,
    ``column``, ``key``) when the file cannot be read."""
    return Scene(_glint.load(_os.fspath(path)))


def default_scene():
    """The scene ``glint view`` opens with no file (built into glint)."""
    return Scene(_glint.default_scene())


class Scene:
    """A loaded scene: render it, inspect it, edit its camera, lights,
    materials and octree parameters (held to the limits scene files are
    held to, refused with :class:`SceneError`)."""

    def __init__(self, native):
        self._native = native

    @classmethod
    def from_toml(cls, text, path="<string>.toml"):
        """A scene from TOML text; ``path`` (ending in ``.toml``) names it
        in errors and anchors relative mesh paths."""
        return cls(_glint.from_toml(text, _os.fspath(path)))

    @property
    def name(self):
        """The scene's path as given to :func:`load`."""
        return self._native.name

    @property
    def load_s(self):
        """Seconds the scene took to load."""
        return self._native.load_s

    @property
    def notes(self):
        """What loading dropped, skipped or could not read."""
        return self._native.notes()

    @property
    def shapes(self):
        """Shapes by kind, e.g. ``{"sphere": 3, "triangle": 12}``."""
        return dict(self._native.shape_counts())

    @property
    def camera(self):
        """The camera: ``eye``, ``lookat``, ``up``, ``fov`` (degrees).
        Assigning a :class:`Viewpoint` (or a mapping of those keys) sets
        all four at once."""
        return Camera(self._native)

    @camera.setter
    def camera(self, value):
        self._native.set_camera(_as_viewpoint(value)._native())

    def turntable(self, n):
        """``n`` cameras (:class:`Viewpoint`) evenly around a full turn:
        the eye turns about the axis through lookat along the camera's up,
        at its distance and height; the first is the scene's camera.
        ``glint render --turntable N`` renders the same cameras."""
        return _turntable(self, n)

    def camera_path(self, fps=None, seconds=None, frames=None):
        """The cameras (:class:`Viewpoint`, with their ``time``) of the
        scene's camera path, ``[[camera.keyframes]]``, as ``glint render
        --path`` renders them: frame k at ``k / fps`` seconds (24 fps
        unless given) to the last key or ``seconds``, or ``frames`` spread
        over it. A ``ValueError`` when the scene has no path."""
        return _camera_path(self, fps, seconds, frames)

    @property
    def lights(self):
        """The point lights, each with ``position`` and ``color``."""
        return Lights(self._native)

    @property
    def materials(self):
        """The materials by name, each with ``color``, ``kd``, ``ks``,
        ``shininess``, ``reflectivity``, ``transparency``, ``ior``."""
        return Materials(self._native)

    @property
    def octree_params(self):
        """The octree the scene renders with: ``enabled``, ``max_depth``,
        ``leaf_size``, ``cost_driven``, ``max_duplication``,
        ``memory_budget_mib``."""
        return OctreeParams(self._native)

    def get(self, key):
        """The value of a scene-file key, e.g. ``"materials.glass.ior"``."""
        return self._native.get(key)

    def set(self, key, value):
        """Sets a scene-file key, e.g. ``set("lights[0].color", (1, 1, 1))``."""
        self._native.set(key, value)

    def keys(self):
        """Every key :meth:`get` reads, in scene-file order."""
        return self._native.keys()

    def copy(self):
        """An independent copy (its edits do not reach this scene)."""
        return Scene(self._native.copy())

    def render(
        self,
        width=None,
        height=None,
        *,
        samples=None,
        aa=None,
        octree=None,
        accel=None,
        max_depth=None,
        view=None,
        threads=None,
        stats=False,
        protocol=None,
        colors=None,
        sides=None,
        cancel=None,
        camera=None,
        frame=None,
        textures=None,
    ):
        """Renders a :class:`Frame`. Unset arguments keep the scene's
        settings, as ``glint render``'s flags do: ``samples`` 1 or 16 or
        ``aa`` ``"off"``, ``"adaptive"``, ``"full"``; ``view`` ``"shaded"``,
        ``"normals"``, ``"depth"``, ``"cost"``, ``"cost-steps"``,
        ``"aa-need"``; ``accel`` ``"octree"``, ``"bvh"`` or ``"none"``
        (what ray queries go through, as ``--accel``: the same image in
        another time; ``octree=False`` is ``"none"``); ``threads`` (default
        one per core). ``stats=True``
        counts the work per ray, as ``--stats`` does (the same image, in
        more time) and fills ``frame.stats``. ``cancel``, an object with
        ``is_set()`` such as ``threading.Event``, stops the render with
        :class:`Cancelled`; Ctrl+C stops it with ``KeyboardInterrupt``.
        ``camera`` (a :class:`Viewpoint` or mapping) renders from there
        instead of the scene's camera; ``frame``, ``(index, count, time)``,
        records the image as that frame of a sequence in its PNG.
        ``textures=False`` draws each textured material in its own colour,
        without cut-outs (``--textures off``)."""
        native = self._native.render(
            width,
            height,
            samples=samples,
            aa=aa,
            octree=octree,
            accel=accel,
            max_depth=max_depth,
            view=view,
            threads=threads,
            stats=stats,
            protocol=protocol,
            colors=colors,
            sides=sides,
            cancel=cancel,
            camera=None if camera is None else _as_viewpoint(camera)._native(),
            frame=frame,
            textures=textures,
        )
        return Frame(native)

    def trace_pixel(self, x, y, **settings):
        """The tree of rays pixel (x, y)'s centre ray spawns, each with its
        octree walk, as nested dicts: ``glint render --trace-pixel X,Y``'s
        JSON. Takes ``width``, ``height``, ``octree``, ``accel``, ``max_depth``,
        ``protocol``, ``colors``, ``sides``, ``textures`` as :meth:`render`
        does."""
        return _json.loads(self._native.trace_pixel(x, y, **settings))

    def octree(self, **params):
        """Builds the octree with these parameters (``max_depth``,
        ``leaf_size``, ``cost_driven``, ``max_duplication``,
        ``memory_budget_mib``; the scene's where not given, and the scene
        keeps its own) and returns ``octree_params``, ``octree_stats``,
        ``build_s`` and ``predicted`` (traversal steps and intersection
        tests per ray, from the tree alone)."""
        return _json.loads(self._native.octree(**params))

    def bench(self, **options):
        """Times the scene with the octree on and off: the record of
        ``glint bench SCENE --format json`` (one scene; no ``--sweep``).
        Takes ``width``, ``height``, ``samples``, ``aa``, ``max_depth``,
        ``view``, ``protocol``, ``colors``, ``sides``, ``repeat`` (3),
        ``threads``, ``octree_only``, ``brute_force_budget`` and
        ``cancel``."""
        return _json.loads(self._native.bench(**options))

    def __repr__(self):
        return repr(self._native)
