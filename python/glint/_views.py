"""Attribute access to a scene's camera, lights, materials and octree
parameters: each attribute is a scene-file key (``scene.lights[0].color``
is ``lights[0].color``), read and set through the scene, so a value a
scene file would refuse is refused with the same message."""

from collections.abc import Mapping, Sequence


class _Keys:
    """Attributes ``FIELDS`` read and set as ``PREFIX + name``."""

    _FIELDS = ()

    def __init__(self, native, prefix):
        object.__setattr__(self, "_native", native)
        object.__setattr__(self, "_prefix", prefix)

    def __getattr__(self, name):
        if name in self._FIELDS:
            return self._native.get(self._prefix + name)
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r} "
                             f"(it has {', '.join(self._FIELDS)})")

    def __setattr__(self, name, value):
        if name not in self._FIELDS:
            raise AttributeError(f"{type(self).__name__} has no attribute {name!r} "
                                 f"(it has {', '.join(self._FIELDS)})")
        self._native.set(self._prefix + name, value)

    def __dir__(self):
        return list(self._FIELDS)

    def as_dict(self):
        """Every attribute and its value."""
        return {name: getattr(self, name) for name in self._FIELDS}

    def __repr__(self):
        fields = ", ".join(f"{k}={v!r}" for k, v in self.as_dict().items())
        return f"{type(self).__name__}({fields})"


class Camera(_Keys):
    _FIELDS = ("eye", "lookat", "up", "fov")

    def __init__(self, native):
        super().__init__(native, "camera.")


class OctreeParams(_Keys):
    _FIELDS = ("enabled", "max_depth", "leaf_size", "cost_driven",
               "max_duplication", "memory_budget_mib")

    def __init__(self, native):
        super().__init__(native, "octree.")


class Light(_Keys):
    _FIELDS = ("position", "color")

    def __init__(self, native, index):
        super().__init__(native, f"lights[{index}].")


class Material(_Keys):
    _FIELDS = ("color", "kd", "ks", "shininess", "reflectivity",
               "transparency", "ior")

    def __init__(self, native, name):
        super().__init__(native, f"materials.{name}.")
        object.__setattr__(self, "name", name)

    def __repr__(self):
        return f"Material({self.name!r}, " + super().__repr__()[len("Material("):]


class Lights(Sequence):
    """The scene's lights, by index."""

    def __init__(self, native):
        self._native = native

    def __len__(self):
        return self._native.light_count()

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(len(self))[index]]
        count = len(self)
        if not -count <= index < count:
            raise IndexError(f"the scene has {count} lights")
        return Light(self._native, index % count)

    def __repr__(self):
        return repr(list(self))


class Materials(Mapping):
    """The scene's materials, by name."""

    def __init__(self, native):
        self._native = native

    def __getitem__(self, name):
        if name not in self._native.material_names():
            raise KeyError(name)
        return Material(self._native, name)

    def __iter__(self):
        return iter(self._native.material_names())

    def __len__(self):
        return len(self._native.material_names())

    def __repr__(self):
        return repr(dict(self))
