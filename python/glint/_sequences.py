"""Sequences of frames (turntables, camera paths) and octree sweeps,
rendered here or as tasks on a Dask cluster.

With ``client=None`` everything runs in this process. With a
``dask.distributed.Client`` (or a scheduler's address), each frame, or
chunk of frames, is a Dask task: the scene goes to the workers once
(scattered), each task renders with glint's own threads (start workers
with ``nthreads=1`` so the two do not fight over cores), and this process
builds each frame from the worker's exact values, so its PNG and record
are byte for byte those of a local render or of ``glint render``. Dask is
an optional extra: ``pip install "glint[dask]"`` (or ``"./python[dask]"``
from a checkout). glint has no scheduler of its own.
"""

import itertools as _itertools
import os as _os
import re as _re
from typing import NamedTuple as _NamedTuple, Optional as _Optional, Tuple as _Tuple

from . import _glint

_DASK_MISSING = (
    "client= runs the work on Dask, which is not installed here: "
    'pip install "glint[dask]" (from a checkout: pip install "./python[dask]")'
)
# How long reaching a scheduler given by address may take.
_CONNECT_TIMEOUT_S = 5


class Viewpoint(_NamedTuple):
    """One camera of a sequence: ``eye``, ``lookat``, ``up`` and ``fov``
    (degrees) as the scene file's ``[camera]`` has them, and ``time``,
    the seconds along the camera path (``None`` for a turntable). Assign
    one to ``scene.camera`` or pass a list to :func:`render_frames`."""

    eye: _Tuple[float, float, float]
    lookat: _Tuple[float, float, float]
    up: _Tuple[float, float, float]
    fov: float
    time: _Optional[float] = None

    def _native(self):
        return (tuple(self.eye), tuple(self.lookat), tuple(self.up), float(self.fov))


def _viewpoint(camera, time=None):
    eye, lookat, up, fov = camera
    return Viewpoint(tuple(eye), tuple(lookat), tuple(up), fov, time)


def as_viewpoint(camera):
    """A :class:`Viewpoint` from one, a mapping with the ``[camera]`` keys,
    or a scene's live ``scene.camera``."""
    if isinstance(camera, Viewpoint):
        return camera
    if hasattr(camera, "as_dict"):
        camera = camera.as_dict()
    try:
        return Viewpoint(
            tuple(camera["eye"]),
            tuple(camera["lookat"]),
            tuple(camera["up"]),
            float(camera["fov"]),
            camera.get("time"),
        )
    except (KeyError, TypeError) as e:
        raise TypeError(
            "a camera is a glint.Viewpoint or a mapping with eye, lookat, up and fov, "
            f"got {camera!r}"
        ) from e


def turntable(scene, n):
    """``n`` cameras around the lookat point, about the camera's up axis,
    at its distance and height; the first is the scene's camera."""
    return [_viewpoint(c) for c in scene._native.turntable(n)]


def camera_path(scene, fps=None, seconds=None, frames=None):
    """The cameras of the scene's camera path (``[[camera.keyframes]]``)
    as ``glint render --path`` renders them: frame k at ``k / fps``
    seconds (24 fps unless given) up to the last key or ``seconds``, or
    ``frames`` spread over it."""
    return [_viewpoint(c, t) for t, c in scene._native.camera_path(fps, seconds, frames)]


def frame_file(pattern, index):
    """The file of frame ``index`` for ``pattern``, as ``glint render -o``
    names them: the last run of ``#`` in the file name becomes the frame
    number, zero-padded to its length; without one, ``_####`` goes before
    the extension."""
    folder, name = _os.path.split(_os.fspath(pattern))
    runs = list(_re.finditer("#+", name))
    if runs:
        run = runs[-1]
        number = str(index).zfill(run.end() - run.start())
        name = name[: run.start()] + number + name[run.end():]
    else:
        stem, dot, ext = name.rpartition(".")
        name = f"{stem}_{index:04d}.{ext}" if dot else f"{name}_{index:04d}"
    return _os.path.join(folder, name)


def _client(client):
    """A Dask client from one or a scheduler's address; a clear error when
    Dask is missing or the scheduler cannot be reached."""
    try:
        import distributed
    except ImportError as e:
        raise ImportError(_DASK_MISSING) from e
    if isinstance(client, str):
        try:
            return distributed.Client(client, timeout=f"{_CONNECT_TIMEOUT_S}s")
        except OSError as e:
            raise OSError(
                f"cannot reach the Dask scheduler at {client} within "
                f"{_CONNECT_TIMEOUT_S} s: {e}"
            ) from e
    return client


# Scenes a worker process has loaded, by their source: each task of a
# sequence finds the scene its first task loaded.
_WORKER_SCENES = {}


def _worker_scene(source):
    """This worker's copy of the scene ``source`` describes: its name, its
    text and the keys the caller had edited."""
    key = (source["name"], source["text"], tuple(sorted(source["edits"].items())),
           source.get("camera"))
    scene = _WORKER_SCENES.get(key)
    if scene is None:
        native = _glint.from_source(source["name"], source["text"])
        for k, v in source["edits"].items():
            if native.get(k) != v:
                native.set(k, v)
        if source.get("camera") is not None:
            native.set_camera(source["camera"])
        _WORKER_SCENES.clear()
        _WORKER_SCENES[key] = scene = native
    return scene


def _source(scene, camera=False):
    """What a worker needs to load ``scene`` again: its name, its text,
    and the value of every key, which the worker sets where its copy
    differs: the edits. The camera goes only with ``camera`` (each frame of
    a sequence brings its own)."""
    name, text = scene._native.source()
    edits = {k: scene.get(k) for k in scene.keys() if not k.startswith("camera.")}
    view = as_viewpoint(scene.camera)._native() if camera else None
    return {"name": name, "text": text, "edits": edits, "camera": view}


def _render_chunk(source, jobs, flags):
    """A Dask task: renders ``jobs`` (index, count, viewpoint) of the
    scene and returns each frame's exact values, or the scene's error as
    data (an exception class of the native module may not unpickle in
    the caller)."""
    try:
        scene = _worker_scene(source)
    except _glint.SceneError as e:
        return ("scene-error", str(e), _error_fields(e))
    out = []
    for index, count, view in jobs:
        frame = scene.render(camera=view._native(), frame=(index, count, view.time), **flags)
        out.append((index, frame.parts()))
    return ("frames", out)


def _error_fields(e):
    return {k: getattr(e, k, None) for k in ("path", "line", "column", "key")}


def _raise_scene_error(message, fields):
    error = _glint.SceneError(message)
    for k, v in fields.items():
        try:
            setattr(error, k, v)
        except AttributeError:
            pass
    raise error


def render_frames(scene, cameras, width=None, height=None, *, out=None, client=None,
                  chunk=1, **render_flags):
    """Renders ``cameras`` (from :meth:`Scene.turntable`,
    :meth:`Scene.camera_path`, or any :class:`Viewpoint` or camera
    mappings) and yields ``(index, Frame)`` as each finishes: in order
    here, in the order they complete on Dask. With ``out`` (a pattern such
    as ``"frames/f_####.png"``, numbered as ``glint render -o``), each
    frame is written there, by this process, through a temporary file, as
    soon as it arrives. ``render_flags`` are :meth:`Scene.render`'s
    (``samples``, ``aa``, ``view``, ``accel``, ``max_depth``, ...).

    ``client``: a ``dask.distributed.Client`` or a scheduler's address
    (a client made from an address is closed when the frames are done)
    runs every ``chunk`` frames as one Dask task; a worker lost mid-run
    has its tasks run again elsewhere, and each frame is yielded once. A
    scene the workers cannot load raises its :class:`SceneError` here,
    once, and the remaining tasks are cancelled. The arguments, the
    extra's presence and the scheduler are checked when called, before
    the first frame is asked for."""
    if not (isinstance(chunk, int) and chunk >= 1):
        raise ValueError(f"chunk is how many frames a task renders, at least 1, got {chunk!r}")
    views = [as_viewpoint(c) for c in cameras]
    flags = dict(render_flags, width=width, height=height)
    if out is not None:
        folder = _os.path.dirname(frame_file(out, 0))
        if folder:
            _os.makedirs(folder, exist_ok=True)

    def finished(index, frame):
        if out is not None:
            frame.save(frame_file(out, index))
        return index, frame

    if client is None:
        return _render_here(scene, views, flags, finished)
    owned, client = isinstance(client, str), _client(client)
    return _render_on_dask(scene, views, flags, (client, owned), chunk, finished)


def _render_here(scene, views, flags, finished):
    from ._frame import Frame

    count = len(views)
    for index, view in enumerate(views):
        native = scene._native.render(
            camera=view._native(), frame=(index, count, view.time), **flags)
        yield finished(index, Frame(native))


def _completed(client, owned, futures):
    """Each future's result as it completes; a scene error, sent back as
    data, raised once; the futures left cancelled (and a client made here
    closed) when the caller stops, fails or is done."""
    from distributed import as_completed

    try:
        for future in as_completed(list(futures)):
            kind, *payload = future.result()
            if kind == "scene-error":
                _raise_scene_error(*payload)
            yield future, payload[0]
    finally:
        for f in futures:
            if not f.done():
                f.cancel()
        if owned:
            client.close()


def _render_on_dask(scene, views, flags, client_owned, chunk, finished):
    from ._frame import Frame

    client, owned = client_owned
    count = len(views)
    task_flags = {k: v for k, v in flags.items() if k not in ("cancel",)}
    # The scene travels once to every worker; tasks name it. (In a list:
    # Dask scatters a dict's values under the dict's keys.)
    [source] = client.scatter([_source(scene)], broadcast=True, hash=False)
    jobs = [(i, count, v) for i, v in enumerate(views)]
    chunks = [jobs[k:k + chunk] for k in range(0, count, chunk)]
    futures = [
        client.submit(_render_chunk, source, part, task_flags, pure=False)
        for part in chunks
    ]
    parts_flags = {k: v for k, v in flags.items() if k not in ("threads", "stats", "cancel")}
    seen = set()
    for _, frames in _completed(client, owned, futures):
        for index, (header, pixels) in frames:
            if index in seen:
                continue
            seen.add(index)
            view = views[index]
            native = scene._native.frame_from_parts(
                header, pixels, camera=view._native(),
                frame=(index, count, view.time), **parts_flags)
            yield finished(index, Frame(native))


def _bench_task(source, setting, options):
    try:
        native = _worker_scene(source)
    except _glint.SceneError as e:
        return ("scene-error", str(e), _error_fields(e))
    scene = native.copy()
    for key, value in setting.items():
        scene.set(f"octree.{key}", value)
    return ("record", scene.bench(octree_only=True, **options))


def sweep(scenes, settings, *, client=None, **bench_options):
    """Times every scene with every octree setting (a mapping of
    ``max_depth``, ``leaf_size``, ``cost_driven``, ``max_duplication``,
    ``memory_budget_mib``): one task per (scene, setting), here or on
    Dask. Yields ``(scene_index, setting_index, record)`` as each
    finishes, ``record`` being :meth:`Scene.bench`'s with
    ``octree_only=True`` (from the scene's camera as edited);
    ``bench_options`` are that method's."""
    scenes = list(scenes)
    settings = [dict(s) for s in settings]
    pairs = list(_itertools.product(range(len(scenes)), range(len(settings))))
    # A benchmark renders from the scene's own camera: it travels too.
    sources = [_source(s, camera=True) for s in scenes]
    if client is None:
        return _sweep_here(sources, settings, pairs, bench_options)
    owned, client = isinstance(client, str), _client(client)
    return _sweep_on_dask(sources, settings, pairs, bench_options, (client, owned))


def _sweep_here(sources, settings, pairs, options):
    import json as _json

    for i, j in pairs:
        kind, *payload = _bench_task(sources[i], settings[j], options)
        if kind == "scene-error":
            _raise_scene_error(*payload)
        yield i, j, _json.loads(payload[0])


def _sweep_on_dask(sources, settings, pairs, options, client_owned):
    import json as _json

    client, owned = client_owned
    scattered = client.scatter(sources, broadcast=True, hash=False)
    futures = {
        client.submit(_bench_task, scattered[i], settings[j], options, pure=False): (i, j)
        for i, j in pairs
    }
    for future, record in _completed(client, owned, futures):
        i, j = futures[future]
        yield i, j, _json.loads(record)
