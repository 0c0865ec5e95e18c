"""A rendered frame as NumPy arrays, its statistics and its PNG."""

import json as _json
import os as _os

import numpy as _np


class Frame:
    """A rendered image. ``rgb`` holds its values (H x W x 3, float32):
    linear RGB in the shaded view; ``(n + 1) / 2`` in the normals view;
    mean distance and coverage in channels 0 and 1 of the depth view;
    intersection tests, traversal steps and leaves entered per pixel in
    the cost views; the sRGB difference in the aa-need view.
    ``srgb8()`` is the 8-bit picture the PNG holds."""

    def __init__(self, native):
        self._native = native
        self._rgb = None
        self._stats = None

    @property
    def width(self):
        return self._native.width

    @property
    def height(self):
        return self._native.height

    @property
    def view(self):
        """The view the frame shows: ``"shaded"``, ``"cost"``, ..."""
        return self._native.view

    @property
    def rgb(self):
        """The frame's values, H x W x 3, float32 (see the class)."""
        if self._rgb is None:
            values = _np.frombuffer(self._native.values(), dtype="<f4")
            self._rgb = values.reshape(self.height, self.width, 3)
        return self._rgb

    def srgb8(self, legend=False):
        """The 8-bit RGB picture, H x W x 3, uint8: the PNG's pixels
        (with ``legend=True``, the legend strip diagnostic views have
        under the image is included, as in a saved PNG)."""
        data, rows = self._native.srgb8(legend)
        return _np.frombuffer(data, dtype=_np.uint8).reshape(rows, self.width, 3)

    @property
    def stats(self):
        """The ``glint render --stats`` dict, for a render with
        ``stats=True``; ``None`` otherwise."""
        if self._stats is None and self._native.stats_json is not None:
            self._stats = _json.loads(self._native.stats_json)
        return self._stats

    def save(self, path, legend=True):
        """Writes the PNG ``glint render`` writes for these settings, with
        its record (``glint info`` reads it, ``glint render --from-png``
        renders it again, edits included)."""
        self._native.save(_os.fspath(path), legend)

    def _repr_png_(self):
        # What a notebook shows: the picture with its legend, no record.
        return bytes(self._native.png(True))

    def __repr__(self):
        return repr(self._native)
