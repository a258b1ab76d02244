"""Compile a :class:`~ignjax.scenes.model.Scene` to MuJoCo and MJX.

``Scene -> MjSpec -> MjModel (+ MjData after mj_forward) -> mjx.Model``.

* Primitives stay primitives (box, cylinder, sphere, capsule, ellipsoid);
  meshes become mesh geoms. Every geom is static (attached to the world
  body), so the model has zero degrees of freedom.
* Every geom gets a material (one per material class, plus a default), so
  ``mjx.ray`` works (it indexes ``mat_rgba`` by ``geom_matid``) and
  renders show specular differences between wood, metal, glass...
* Geom groups: 0 floor, 1 walls and lintels, 2 objects, 3 structural
  instances (imported walls/floors/doors/windows). Ray queries choose
  groups with ``geomgroup``.
* ``geom_instance[g]`` is the index in ``scene.instances`` of the instance
  geom ``g`` belongs to, or -1 for the building (floor, walls).

Static scenes cannot be run through ``mjx.kinematics`` (MJX's body scan needs
at least one DoF), so the MJX data is made from the C ``mj_forward`` result
with ``mjx.put_data``: world poses of static geoms never change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import mujoco
import numpy as np

from ignjax.scenes.model import Geom, Instance, Scene

GROUP_FLOOR, GROUP_WALL, GROUP_OBJECT, GROUP_STRUCTURAL = 0, 1, 2, 3

_MATERIAL_LOOK = {
    # name: (specular, shininess, reflectance)
    "default": (0.2, 0.2, 0.0),
    "wood": (0.15, 0.25, 0.0),
    "metal": (0.8, 0.8, 0.15),
    "fabric": (0.02, 0.05, 0.0),
    "leather": (0.35, 0.45, 0.0),
    "plastic": (0.45, 0.6, 0.0),
    "glass": (0.9, 0.95, 0.2),
    "ceramic": (0.6, 0.75, 0.05),
    "stone": (0.25, 0.3, 0.0),
    "wicker": (0.05, 0.1, 0.0),
}

_KIND_TO_MJ = {
    "box": mujoco.mjtGeom.mjGEOM_BOX,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
    "ellipsoid": mujoco.mjtGeom.mjGEOM_ELLIPSOID,
    "mesh": mujoco.mjtGeom.mjGEOM_MESH,
}


@dataclass(frozen=True)
class CompileOptions:
    """Static options of compilation.

    Attributes:
        floor_margin: how far the visible floor extends beyond the scene, m.
        offscreen_size: (width, height) of MuJoCo's offscreen buffer; the
            largest image :mod:`ignjax.scenes.viz.render` can produce.
        shadows: whether the lights cast shadows (slower to render).
    """

    floor_margin: float = 1.0
    offscreen_size: tuple[int, int] = (1024, 1024)
    shadows: bool = False


def quat_mul(a, b) -> np.ndarray:
    """Hamilton product of quaternions (w, x, y, z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array([
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ])


def yaw_quat(yaw: float) -> np.ndarray:
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def geom_world_pose(inst: Instance, g: Geom) -> tuple[np.ndarray, np.ndarray]:
    """World position (3,) and quaternion (4,) of an instance's geom."""
    c, s = math.cos(inst.yaw), math.sin(inst.yaw)
    lx, ly, lz = g.pos
    pos = np.array([inst.position[0] + c * lx - s * ly, inst.position[1] + s * lx + c * ly, inst.position[2] + lz])
    quat = quat_mul(yaw_quat(inst.yaw), np.asarray(g.quat, dtype=np.float64))
    return pos, quat / np.linalg.norm(quat)


@dataclass(eq=False)
class CompiledScene:
    """A scene compiled to MuJoCo.

    Attributes:
        scene: the source scene.
        model: the compiled ``mujoco.MjModel``.
        data: ``mujoco.MjData`` after ``mj_forward`` (geom world poses set).
        geom_instance: (ngeom,) int32, index into ``scene.instances`` or -1.
        options: the options used.
    """

    scene: Scene
    model: mujoco.MjModel
    data: mujoco.MjData
    geom_instance: np.ndarray
    options: CompileOptions = field(default_factory=CompileOptions)

    @property
    def ngeom(self) -> int:
        return int(self.model.ngeom)

    @cached_property
    def mjx_model(self):
        """The ``mjx.Model`` (JAX implementation) of this scene."""
        from mujoco import mjx  # on use: importing mujoco.mjx takes about 3 s

        return mjx.put_model(self.model, impl="jax")

    @cached_property
    def mjx_data(self):
        """``mjx.Data`` with the static geom poses of ``data``."""
        from mujoco import mjx  # on use: importing mujoco.mjx takes about 3 s

        return mjx.put_data(self.model, self.data, impl="jax")

    def instance_geoms(self, index: int) -> np.ndarray:
        """Geom ids of ``scene.instances[index]``."""
        return np.nonzero(self.geom_instance == index)[0]


def build_spec(scene: Scene, options: CompileOptions = CompileOptions()) -> tuple[mujoco.MjSpec, list[int]]:
    """Build the ``MjSpec`` of a scene.

    Returns:
        The spec and, per geom in creation order, the instance index or -1.
    """
    spec = mujoco.MjSpec()
    spec.modelname = _safe_name(scene.id) or "scene"
    spec.visual.global_.offwidth = int(options.offscreen_size[0])
    spec.visual.global_.offheight = int(options.offscreen_size[1])
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.45, 0.45, 0.45]
    spec.visual.headlight.specular = [0.1, 0.1, 0.1]
    spec.visual.quality.shadowsize = 2048 if options.shadows else 0

    for name, (specular, shininess, reflectance) in _MATERIAL_LOOK.items():
        mat = spec.add_material(name=f"mat_{name}")
        mat.specular = specular
        mat.shininess = shininess
        mat.reflectance = reflectance
    tex = spec.add_texture(name="floor_tex", type=mujoco.mjtTexture.mjTEXTURE_2D, builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
                           rgb1=[0.78, 0.74, 0.68], rgb2=[0.70, 0.66, 0.60], width=256, height=256)
    floor_mat = spec.add_material(name="mat_floor")
    floor_mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
    floor_mat.texrepeat = [2.0, 2.0]
    floor_mat.texuniform = True
    spec.add_texture(name="sky", type=mujoco.mjtTexture.mjTEXTURE_SKYBOX, builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
                     rgb1=[0.75, 0.85, 0.95], rgb2=[0.35, 0.45, 0.6], width=64, height=64)
    wall_mat = spec.add_material(name="mat_wall")
    wall_mat.specular = 0.05

    world = spec.worldbody
    geom_instance: list[int] = []
    lo, hi = scene.bounds()
    span = float(max(hi[0] - lo[0], hi[1] - lo[1], 1.0))
    center = (lo[:2] + hi[:2]) / 2

    # floor: a plane at z = 0 (finite for rendering, infinite for rays)
    half = span / 2 + options.floor_margin
    world.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[half, half, 0.05],
                   pos=[float(center[0]), float(center[1]), 0.0], material="mat_floor", rgba=[1, 1, 1, 1],
                   group=GROUP_FLOOR, contype=0, conaffinity=0)
    geom_instance.append(-1)

    for w in scene.walls:
        length = w.length
        if length < 1e-6 or w.height <= 0:
            continue
        yaw = math.atan2(w.end[1] - w.start[1], w.end[0] - w.start[0])
        mid = ((w.start[0] + w.end[0]) / 2, (w.start[1] + w.end[1]) / 2)
        world.add_geom(name=f"wall:{_safe_name(w.id)}", type=mujoco.mjtGeom.mjGEOM_BOX,
                       size=[length / 2 + w.thickness / 2, w.thickness / 2, w.height / 2],
                       pos=[mid[0], mid[1], w.bottom + w.height / 2], quat=list(yaw_quat(yaw)),
                       material="mat_wall", rgba=[0.93, 0.92, 0.89, 1.0], group=GROUP_WALL, contype=0, conaffinity=0)
        geom_instance.append(-1)

    for idx, inst in enumerate(scene.instances):
        geoms = inst.geoms or (_bbox_geom(inst),)
        for k, g in enumerate(geoms):
            pos, quat = geom_world_pose(inst, g) if inst.geoms else (np.array(inst.bbox.center), yaw_quat(inst.bbox.yaw))
            kwargs = dict(name=f"{_safe_name(inst.id)}:{k}", pos=[float(v) for v in pos], quat=[float(v) for v in quat],
                          rgba=list(g.rgba), material=f"mat_{g.material if g.material in _MATERIAL_LOOK else 'default'}",
                          group=GROUP_STRUCTURAL if inst.structural else GROUP_OBJECT, contype=0, conaffinity=0)
            if g.kind == "mesh":
                mesh_name = f"mesh:{_safe_name(inst.id)}:{k}"
                mesh = spec.add_mesh(name=mesh_name)
                mesh.uservert = g.mesh.vertices.astype(np.float64).ravel().tolist()
                mesh.userface = g.mesh.faces.astype(np.int32).ravel().tolist()
                mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
                world.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname=mesh_name, **kwargs)
            else:
                world.add_geom(type=_KIND_TO_MJ[g.kind], size=list(g.size), **kwargs)
            geom_instance.append(idx)

    # lights: soft directional lights from above, plus the headlight
    for k, (dx, dy) in enumerate(((0.3, 0.2), (-0.25, -0.35))):
        light = world.add_light(name=f"sun{k}", pos=[float(center[0]), float(center[1]), 6.0], dir=[dx, dy, -1.0])
        light.type = mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
        light.diffuse = [0.45, 0.45, 0.43]
        light.specular = [0.15, 0.15, 0.15]
        light.castshadow = bool(options.shadows)
    return spec, geom_instance


def compile_scene(scene: Scene, options: CompileOptions = CompileOptions()) -> CompiledScene:
    """Compile a scene to MuJoCo (``MjModel`` + forward-computed ``MjData``)."""
    spec, geom_instance = build_spec(scene, options)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    gi = np.asarray(geom_instance, dtype=np.int32)
    assert gi.shape[0] == model.ngeom, (gi.shape, model.ngeom)
    return CompiledScene(scene=scene, model=model, data=data, geom_instance=gi, options=options)


def _bbox_geom(inst: Instance) -> Geom:
    """A box filling an instance's bounding box (for instances with no geometry)."""
    return Geom("box", inst.bbox.half_extents, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), (0.6, 0.6, 0.6, 1.0), "bbox")


def _safe_name(text: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "_-.:" else "_" for ch in str(text))
