"""The optional `mjcf:` section of a spec: MuJoCo-only scene settings.

Everything here is written into the MJCF as MuJoCo spells it (MuJoCo XML reference), so units
are MuJoCo's: lengths in m, `fovy`, `azimuth` and `elevation` in degrees, colours 0..1. A spec
without this section gets simkit's plain defaults (one overhead light, timestep 0.002 s,
position servos in the main file), so arm kits do not change.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

# Own base types (not imported from spec.py, which imports this module).
Vec3 = tuple[float, float, float]
Rgba = tuple[float, float, float, float]
PositiveFloat = Annotated[float, Field(gt=0)]
NonNegFloat = Annotated[float, Field(ge=0)]
Quat = tuple[float, float, float, float]
PositiveInt = Annotated[int, Field(gt=0)]
NonNegInt = Annotated[int, Field(ge=0)]
Loc = tuple
Problem = tuple[Loc, str]

#: Default classes simkit always writes (geoms of every link use them); a spec class with one
#: of these names adds attributes to it instead of defining a new class.
BUILTIN_CLASSES = ("visual", "collision")


class Strict(BaseModel):
    """Base: frozen, no unknown keys, finite floats only (as spec.Strict)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class Headlight(Strict):
    diffuse: Vec3 | None = None
    ambient: Vec3 | None = None
    specular: Vec3 | None = None


class VisualSpec(Strict):
    """`<visual>`: offscreen buffer size (pixels), free camera angles (deg), headlight, haze."""

    offwidth: PositiveInt | None = None
    offheight: PositiveInt | None = None
    azimuth: float | None = None
    elevation: float | None = None
    headlight: Headlight | None = None
    haze: Rgba | None = None


class DefaultJoint(Strict):
    damping: NonNegFloat | None = None
    armature: NonNegFloat | None = None
    frictionloss: NonNegFloat | None = None


class DefaultGeom(Strict):
    type: Literal["plane", "sphere", "capsule", "ellipsoid", "cylinder", "box", "mesh"] | None = (
        None
    )
    size: tuple[PositiveFloat, ...] | None = None
    material: str | None = None
    rgba: Rgba | None = None
    contype: NonNegInt | None = None
    conaffinity: NonNegInt | None = None
    group: NonNegInt | None = None
    condim: Literal[1, 3, 4, 6] | None = None
    friction: Vec3 | None = None


class DefaultClass(Strict):
    """A `<default class>`; `parent` nests it in another class (None: the robot's class)."""

    name: str
    parent: str | None = None
    joint: DefaultJoint | None = None
    geom: DefaultGeom | None = None


class TextureSpec(Strict):
    name: str
    type: Literal["2d", "cube", "skybox"] = "2d"
    builtin: Literal["none", "gradient", "checker", "flat"] = "none"
    mark: Literal["none", "edge", "cross", "random"] | None = None
    rgb1: Vec3 | None = None
    rgb2: Vec3 | None = None
    markrgb: Vec3 | None = None
    width: PositiveInt | None = None
    height: PositiveInt | None = None


class SceneMaterialSpec(Strict):
    """An MJCF-only material (textured floors...); robot colours stay in `materials`."""

    name: str
    rgba: Rgba | None = None
    texture: str | None = None
    texuniform: bool | None = None
    texrepeat: tuple[float, float] | None = None
    reflectance: Annotated[float, Field(ge=0, le=1)] | None = None


class FloorSpec(Strict):
    """A ground plane in the world body; size (m) as MuJoCo's plane: half x, half y, grid."""

    name: str = "floor"
    size: Vec3 = (0.0, 0.0, 0.05)
    material: str | None = None
    contype: NonNegInt | None = None
    conaffinity: NonNegInt | None = None


class LightSpec(Strict):
    name: str | None = None
    pos: Vec3 = (0.0, 0.0, 3.0)
    dir: Vec3 = (0.0, 0.0, -1.0)
    directional: bool = False
    diffuse: Vec3 | None = None
    specular: Vec3 | None = None


class CameraSpec(Strict):
    """A camera on a link (`body`) or in the world; `quat` is (w, x, y, z), `fovy` in deg."""

    name: str
    body: str | None = None
    mode: Literal["fixed", "track", "trackcom", "targetbody", "targetbodycom"] = "fixed"
    fovy: Annotated[float, Field(gt=0, lt=180)] | None = None
    pos: Vec3 = (0.0, 0.0, 0.0)
    quat: Quat | None = None
    estimated: tuple[str, ...] = ()


SITE_SENSORS = ("gyro", "velocimeter", "accelerometer", "magnetometer", "touch", "force", "torque")
OBJECT_SENSORS = (
    "framequat",
    "framepos",
    "framexaxis",
    "frameyaxis",
    "framezaxis",
    "framelinvel",
    "frameangvel",
)
BODY_SENSORS = ("subtreeangmom", "subtreecom", "subtreelinvel")


class SensorSpec(Strict):
    """One `<sensor>` child: site sensors need `site`, frame sensors `objtype`/`objname`,
    subtree sensors `body`."""

    type: Literal[SITE_SENSORS + OBJECT_SENSORS + BODY_SENSORS]  # type: ignore[valid-type]
    name: str
    site: str | None = None
    objtype: Literal["site", "body", "xbody", "geom", "camera"] | None = None
    objname: str | None = None
    body: str | None = None

    @model_validator(mode="after")
    def _refs(self) -> SensorSpec:
        need = (
            ("site",)
            if self.type in SITE_SENSORS
            else (("objtype", "objname") if self.type in OBJECT_SENSORS else ("body",))
        )
        for name in need:
            if getattr(self, name) is None:
                raise ValueError(f"a {self.type} sensor needs '{name}'")
        return self


class MjcfSpec(Strict):
    """MuJoCo scene settings. `actuators: scene` keeps the main file free of actuators (as
    robots whose controllers add them at run time ship it) and writes the position servos
    into a second file, `mjcf/NAME_scene.xml`, that includes the main one."""

    timestep: PositiveFloat = 0.002
    actuators: Literal["main", "scene"] = "main"
    visual: VisualSpec | None = None
    defaults: tuple[DefaultClass, ...] = ()
    textures: tuple[TextureSpec, ...] = ()
    materials: tuple[SceneMaterialSpec, ...] = ()
    floor: FloorSpec | None = None
    lights: tuple[LightSpec, ...] = ()
    cameras: tuple[CameraSpec, ...] = ()
    sensors: tuple[SensorSpec, ...] = ()


def problems(spec, links: set[str], sites: set[str]) -> Iterator[Problem]:
    """Cross-references inside `spec.mjcf` and from joints and collision primitives to it."""
    mj: MjcfSpec | None = spec.mjcf
    classes = set(BUILTIN_CLASSES) | {c.name for c in (mj.defaults if mj else ())}
    if mj is not None:
        materials = {m.name for m in spec.materials} | {m.name for m in mj.materials}
        textures = {t.name for t in mj.textures}
        seen: set[str] = set(BUILTIN_CLASSES)
        for i, cls in enumerate(mj.defaults):
            if cls.parent is not None and cls.parent not in seen:
                yield (
                    ("mjcf", "defaults", i, "parent"),
                    f"class '{cls.parent}' is not defined above",
                )
            if cls.geom is not None and cls.geom.material and cls.geom.material not in materials:
                yield (
                    ("mjcf", "defaults", i, "geom", "material"),
                    f"unknown material '{cls.geom.material}'",
                )
            seen.add(cls.name)
        for i, mat in enumerate(mj.materials):
            if mat.texture is not None and mat.texture not in textures:
                yield ("mjcf", "materials", i, "texture"), f"unknown texture '{mat.texture}'"
        if mj.floor is not None and mj.floor.material and mj.floor.material not in materials:
            yield ("mjcf", "floor", "material"), f"unknown material '{mj.floor.material}'"
        for i, cam in enumerate(mj.cameras):
            if cam.body is not None and cam.body not in links:
                yield ("mjcf", "cameras", i, "body"), f"unknown link '{cam.body}'"
        for i, sensor in enumerate(mj.sensors):
            for key, known, what in (("site", sites, "frame"), ("body", links, "link")):
                value = getattr(sensor, key)
                if value is not None and value not in known:
                    yield ("mjcf", "sensors", i, key), f"unknown {what} '{value}'"
            if sensor.objtype in ("site", "body", "xbody") and sensor.objname not in (
                sites if sensor.objtype == "site" else links
            ):
                yield (
                    ("mjcf", "sensors", i, "objname"),
                    f"unknown {sensor.objtype} '{sensor.objname}'",
                )
    for i, joint in enumerate(spec.joints):
        if joint.mjcf_class is not None and joint.mjcf_class not in classes:
            yield ("joints", i, "mjcf_class"), f"unknown MJCF default class '{joint.mjcf_class}'"
    for i, link in enumerate(spec.links):
        for k, prim in enumerate(link.collision_primitives):
            if prim.geom_class is not None and prim.geom_class not in classes:
                yield (
                    ("links", i, "collision_primitives", k, "geom_class"),
                    f"unknown MJCF default class '{prim.geom_class}'",
                )
