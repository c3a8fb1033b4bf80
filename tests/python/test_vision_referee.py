"""Issue 30, "Done means": gantry's vision sensor against an independent renderer.

The referee is PyBullet's CPU renderer (TinyRenderer: ``getCameraImage`` with
``renderer=ER_TINY_RENDERER`` in DIRECT mode), which shares nothing with gantry but the
files. Each scene is a public URDF arm (the files of ``pybullet_data`` and
``example-robot-data``, found by ``public_robots.py``; a missing file is a failure, not a
skip) in a non-trivial joint configuration, on a floor, with a few boxes, seen by one
camera. gantry (the in-process ``gantry.Client``, a scene file written to ``tmp_path``)
and PyBullet load the same files, set the same joint angles and look from the same pose
with the same intrinsics; then

* ``test_depth_matches_tinyrenderer``: gantry's depth in metres agrees with PyBullet's
  within DEPTH_TOL (relative) on at least MIN_AGREEMENT of the pixels away from
  silhouette edges;
* ``test_mask_matches_segmentation``: gantry's mask (the handle of the shape seen at each
  pixel, ``client.mask``) agrees with PyBullet's segmentation buffer, mapped from
  (body, link) to gantry's handles, on at least MIN_AGREEMENT of the non-edge pixels.
  On gantry's side the same mask must also come, pixel for pixel, from
  ``sim.getVisionSensorMask`` (what Lua and ZMQ clients read) and from CoppeliaSim's
  colour-coded render mode (handle = r + 256 g + 65536 b, as PyRep and RLBench decode it).

Both also hold each object (a link, the floor, a box) seen on at least OBJECT_MIN_PIXELS
compared pixels to OBJECT_MIN_AGREEMENT of them: a link that is half missing can be well
under 1 % of the image (the UR5's missing upper-arm tube is), and the image-wide
criterion alone would pass it. (That is how this test found gantry's mesh loader
pointing the triangles of a file's third sub-mesh on at the wrong vertices, fixed since:
the UR5's upper arm agreed on 7.9 % of its pixels, the Panda's link6 on 28 %.) The comparison also asks that most of the image is compared
(MIN_COMPARED) and that the robot is really in view (MIN_ROBOT_PIXELS), so it cannot pass
by looking at the floor. ``test_gantry_floor_depth_is_analytic`` checks gantry's floor
against the closed-form depth, without PyBullet.

Conventions, which is where a comparison like this goes wrong:

* **Camera frames.** A gantry vision sensor looks along its local +Z; image up is local
  +Y and image right is local -X (CoppeliaSim's convention). PyBullet's view matrix is
  OpenGL's: the camera looks along its local -Z, up is +Y, right is +X, and
  ``computeViewMatrix(eye, target, up)`` builds it like ``gluLookAt``. Both are made
  here from one (eye, target, world up): forward f, right r = f x up, up u = r x f; the
  gantry sensor's rotation has columns (-r, u, f).
* **Field of view.** gantry's ``fov_deg`` spans the *larger* image side (the width of a
  160 x 120 image); PyBullet's ``computeProjectionMatrixFOV`` takes the *vertical* angle:
  tan(v / 2) = tan(h / 2) * height / width.
* **Depth.** gantry's depth (``client.depth(h, metres=True)``) is planar: the distance
  along the optical axis, in metres, top row first. PyBullet's depth buffer is OpenGL's
  non-linear window depth b in [0, 1]; the planar depth is
  near * far / (far - (far - near) * b). Where nothing is seen, gantry gives ``far`` and
  PyBullet b = 1, which is also ``far``.
* **Where a pixel is sampled.** gantry samples each pixel at its centre. TinyRenderer
  samples at integer window coordinates, the lower-left *corner* of each pixel, so its
  whole image is half a pixel off (on a tilted floor that is a 1 % depth difference
  everywhere, and a silhouette may move by a pixel). The referee shifts PyBullet's
  projection by half a pixel in x and y (``half_pixel_shift``) so that both sample the
  same rays; ``test_tinyrenderer_samples_pixel_corners`` pins that fact down against the
  analytic depth of the floor, so the shift cannot hide a gantry error.
* **Edges.** A pixel is an edge pixel, and not compared, when its 3 x 3 neighbourhood
  holds, in either image, a depth that differs from its own by more than EDGE_JUMP
  (relative) or a different object. Two rasterisers legitimately disagree there by one
  pixel; everywhere else they must see the same surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest

import gantry
from public_robots import BY_ID, Robot, UrdfInfo, example_robot_data_share, limited

# Image size: small so that the suite stays quick, large enough for 19,200 samples.
WIDTH, HEIGHT = 160, 120
# The sensor's view angle across the image's larger side (its width), degrees.
FOV_DEG = 60.0
# Clipping planes, metres. Everything in the scenes lies between them.
NEAR, FAR = 0.05, 10.0
# Agreement asked of the non-edge pixels: depth within 1 % (relative), and the fraction.
DEPTH_TOL = 0.01
MIN_AGREEMENT = 0.99
# A neighbour's depth differing by more than this (relative) makes a pixel an edge pixel.
EDGE_JUMP = 0.02
# The comparison must not become vacuous: at least this fraction of the image is
# compared, and at least this many compared pixels see the robot.
MIN_COMPARED = 0.5
MIN_ROBOT_PIXELS = 400
# Every object with at least this many compared pixels must agree on this fraction of them.
OBJECT_MIN_PIXELS = 40
OBJECT_MIN_AGREEMENT = 0.95

FLOOR_SIZE = (5.0, 5.0)  # gantry's default [floor]: a 5 x 5 x 0.1 m box, top face at z = 0


@dataclass(frozen=True)
class Box:
    """A static box standing on the floor: full extents (m), centre (m), yaw about Z (deg)."""

    name: str
    size: tuple[float, float, float]
    position: tuple[float, float, float]
    yaw_deg: float = 0.0


@dataclass(frozen=True)
class Camera:
    """A vision sensor: name, resolution (px), and its eye and target (m) with a world up
    direction, from which both sides build the same pose (``camera_axes``)."""

    name: str
    width: int
    height: int
    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Scene:
    """One referee scene: a public robot at the world origin (fixed base), joint angles by
    URDF joint name (radians or metres), boxes, and the camera's eye and target (m)."""

    sid: str
    robot: Robot
    joints: dict[str, float]
    boxes: tuple[Box, ...]
    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = field(default=(0.0, 0.0, 1.0))

    @property
    def camera(self) -> Camera:
        """The referee's camera: WIDTH x HEIGHT, named ``camera``."""
        return Camera("camera", WIDTH, HEIGHT, self.eye, self.target, self.up)


SCENE_LIST = [
    Scene(
        "ur5",
        BY_ID["ur5"],
        {"shoulder_pan_joint": 0.6, "shoulder_lift_joint": -1.1, "elbow_joint": 1.4,
         "wrist_1_joint": -0.9, "wrist_2_joint": -1.3, "wrist_3_joint": 0.7},
        (Box("box_a", (0.2, 0.3, 0.25), (0.55, 0.35, 0.125), 20.0),
         Box("box_b", (0.15, 0.15, 0.4), (-0.4, 0.5, 0.2), -35.0)),
        eye=(1.0, -0.75, 0.85), target=(0.05, 0.15, 0.3),
    ),
    Scene(
        "pb_panda",
        BY_ID["pb_panda"],
        {"panda_joint1": -0.5, "panda_joint2": 0.4, "panda_joint3": 0.3, "panda_joint4": -2.0,
         "panda_joint5": 0.5, "panda_joint6": 1.8, "panda_joint7": 0.9,
         "panda_finger_joint1": 0.03, "panda_finger_joint2": 0.03},
        (Box("box_a", (0.25, 0.25, 0.2), (0.5, -0.3, 0.1), 30.0),
         Box("box_b", (0.1, 0.4, 0.3), (0.3, 0.5, 0.15), 0.0)),
        eye=(1.1, 0.8, 0.9), target=(0.25, 0.05, 0.35),
    ),
    Scene(
        "kuka_iiwa",
        BY_ID["kuka_iiwa"],
        {"lbr_iiwa_joint_1": 0.5, "lbr_iiwa_joint_2": 0.6, "lbr_iiwa_joint_3": -0.3,
         "lbr_iiwa_joint_4": -1.2, "lbr_iiwa_joint_5": 0.4, "lbr_iiwa_joint_6": 0.9,
         "lbr_iiwa_joint_7": 0.2},
        (Box("box_a", (0.3, 0.2, 0.3), (0.6, -0.5, 0.15), 10.0),
         Box("box_b", (0.2, 0.2, 0.2), (-0.3, -0.6, 0.1), 45.0)),
        eye=(1.1, -0.9, 1.0), target=(0.0, 0.0, 0.55),
    ),
    Scene(
        "xarm6",
        BY_ID["xarm6"],
        {"joint1": -0.8, "joint2": -0.3, "joint3": -0.9, "joint4": 0.6, "joint5": 1.0, "joint6": -0.4},
        (Box("box_a", (0.2, 0.2, 0.15), (0.35, -0.45, 0.075), 15.0),
         Box("box_b", (0.3, 0.1, 0.35), (-0.3, 0.3, 0.175), 60.0)),
        eye=(-0.7, -0.9, 0.75), target=(0.05, -0.1, 0.25),
    ),
    Scene(
        "xarm7",
        BY_ID["xarm7"],
        {"joint1": 0.7, "joint2": 0.5, "joint3": -0.6, "joint4": 1.2, "joint5": 0.8, "joint6": 0.9,
         "joint7": -1.0},
        (Box("box_a", (0.15, 0.25, 0.2), (0.45, 0.1, 0.1), -20.0),
         Box("box_b", (0.25, 0.2, 0.1), (0.1, 0.45, 0.05), 40.0)),
        eye=(0.9, 0.9, 0.8), target=(0.15, 0.1, 0.3),
    ),
]
SCENE_BY_ID = {s.sid: s for s in SCENE_LIST}


# ---------------------------------------------------------------------------------------
# Camera geometry shared by both sides


def camera_axes(cam: Camera | Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(forward, right, up) unit vectors in the world, as ``gluLookAt`` builds them."""
    eye, target, up = (np.asarray(v, dtype=float) for v in (cam.eye, cam.target, cam.up))
    f = target - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    return f, r, np.cross(r, f)


def sensor_quaternion(cam: Camera | Scene) -> list[float]:
    """The gantry sensor's world orientation as [x, y, z, w]: local +Z forward, local +Y
    up, local +X to the image's *left* (so image right is local -X)."""
    f, r, u = camera_axes(cam)
    m = np.column_stack([-r, u, f])
    # Shepperd's method on the largest of the four candidates, for accuracy.
    tr = np.trace(m)
    candidates = [tr, m[0, 0], m[1, 1], m[2, 2]]
    k = int(np.argmax(candidates))
    if k == 0:
        s = 2.0 * math.sqrt(1.0 + tr)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4]
    elif k == 1:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif k == 2:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s]
    return [float(c) for c in q]


def vertical_fov_deg(width: int = WIDTH, height: int = HEIGHT, fov_deg: float = FOV_DEG) -> float:
    """PyBullet's (vertical) fov for gantry's angle across the larger image side."""
    half = math.tan(math.radians(fov_deg) / 2)
    if width >= height:
        half *= height / width
    return math.degrees(2 * math.atan(half))


def half_pixel_shift(proj: list[float], width: int, height: int) -> list[float]:
    """``proj`` (OpenGL, column-major) with the image moved half a pixel left and down.

    TinyRenderer samples pixel (i, j) at window coordinates (i, j), its lower-left corner;
    gantry at (i + 0.5, j + 0.5). Moving every point by -0.5 pixel, which is -1/width in
    normalised device x (and -1/height in y), puts at TinyRenderer's sample what lies at the
    pixel's centre. x_ndc = x_clip / w_clip with w_clip = -z_eye, so adding d to x_ndc
    adds d * (-z_eye) to x_clip: the matrix entry (row 0, column 2) loses d.
    """
    out = list(proj)
    out[8] += 1.0 / width  # row 0, column 2: x_ndc - 1/width
    out[9] += 1.0 / height  # row 1, column 2: y_ndc - 1/height
    return out


def pybullet_depth_metres(buffer: np.ndarray, near: float = NEAR, far: float = FAR) -> np.ndarray:
    """Planar depth (m) from OpenGL's non-linear window depth b in [0, 1]."""
    b = np.asarray(buffer, dtype=np.float64)
    return near * far / (far - (far - near) * b)


def floor_depth(scene: Scene, rows: np.ndarray, cols: np.ndarray, row_offset: float,
                col_offset: float) -> np.ndarray:
    """Analytic planar depth of the plane z = 0 at image positions (col + col_offset,
    row + row_offset), measured from the image's top-left corner in pixels, for the
    scene's camera; rays that miss the plane give inf."""
    f, r, u = camera_axes(scene)
    half_w = math.tan(math.radians(FOV_DEG) / 2)
    half_h = half_w * HEIGHT / WIDTH
    x = ((cols + col_offset) / WIDTH * 2 - 1) * half_w
    y = (1 - (rows + row_offset) / HEIGHT * 2) * half_h
    # A ray with unit forward component: its parameter at the plane is the planar depth.
    dz = f[2] + x * r[2] + y * u[2]
    with np.errstate(divide="ignore"):
        t = -scene.eye[2] / dz
    return np.where(t > 0, t, np.inf)


# ---------------------------------------------------------------------------------------
# The two renderers


def check_configuration(scene: Scene) -> None:
    """The scene's joint angles name movable joints of the file, inside their limits (so
    neither side can clamp them differently)."""
    info = UrdfInfo.parse(scene.robot.path.read_text(errors="replace"))
    movable = {j.name: j for j in info.movable}
    for name, value in scene.joints.items():
        assert name in movable, f"{scene.sid}: {name} is not a movable joint of {scene.robot.path}"
        j = movable[name]
        if limited(j):
            assert j.lower <= value <= j.upper, f"{scene.sid}: {name} = {value} outside [{j.lower}, {j.upper}]"


def toml_list(values) -> str:
    return "[" + ", ".join(repr(float(v)) for v in values) + "]"


def gantry_scene_text(scene: Scene, cameras: list[Camera] | None = None) -> str:
    """The gantry scene file: floor, robot (joint angles as ``initial``, in degrees for
    revolute joints and metres for prismatic ones), boxes, and ``cameras`` (default: the
    scene's camera) as vision sensors."""
    info = UrdfInfo.parse(scene.robot.path.read_text(errors="replace"))
    types = {j.name: j.type for j in info.joints}
    initial = ", ".join(
        f"{name} = {math.degrees(v) if types[name] != 'prismatic' else v!r}" for name, v in scene.joints.items()
    )
    lines = [
        "[floor]",
        f"size = {toml_list(FLOOR_SIZE)}",
        "",
        "[[robot]]",
        f"urdf = {str(scene.robot.path)!r}",
        'name = "robot"',
        f"initial = {{ {initial} }}",
    ]
    for box in scene.boxes:
        lines += [
            "",
            "[[object]]",
            f'name = "{box.name}"',
            'kind = "shape"',
            'shape = "box"',
            f"size = {toml_list(box.size)}",
            f"position = {toml_list(box.position)}",
            f"orientation_deg = {toml_list((0, 0, box.yaw_deg))}",
        ]
    for cam in cameras or [scene.camera]:
        lines += [
            "",
            "[[object]]",
            f'name = "{cam.name}"',
            'kind = "vision_sensor"',
            f"resolution = [{cam.width}, {cam.height}]",
            f"fov_deg = {FOV_DEG!r}",
            f"near = {NEAR!r}",
            f"far = {FAR!r}",
            f"position = {toml_list(cam.eye)}",
            f"quaternion = {toml_list(sensor_quaternion(cam))}",
        ]
    return "\n".join(lines) + "\n"


@dataclass
class GantryView:
    depth: np.ndarray  # (HEIGHT, WIDTH) float64, metres, top row first
    mask: np.ndarray | None  # (HEIGHT, WIDTH) int32 handles, -1 for nothing; None if not asked
    handles: dict[str, int]  # "link:NAME", "Floor", box names -> shape handle


def render_gantry(scene: Scene, tmp_path: Path, *, mask: bool = False) -> GantryView:
    path = tmp_path / f"{scene.sid}.toml"
    path.write_text(gantry_scene_text(scene))
    package_paths = [example_robot_data_share()] if scene.robot.package_paths else []
    with gantry.Client(path, scripts=False, realtime=False, package_paths=package_paths) as client:
        sim = client.require("sim")
        sensor = sim.getObject("/camera")
        sim.handleVisionSensor(sensor)
        depth = np.array(client.depth(sensor, metres=True), dtype=np.float64)
        seen = None
        if mask:
            seen = np.array(client.mask(sensor, top_first=True))
            # The same mask through the sim API (what Lua and ZMQ clients read): int32
            # little-endian, bottom row first.
            raw, (w, h) = sim.getVisionSensorMask(sensor)
            api = np.frombuffer(raw, "<i4").reshape(h, w)[::-1]
            assert np.array_equal(api, seen), "sim.getVisionSensorMask and client.mask differ"
            # And CoppeliaSim's colour-coded render mode, as PyRep and RLBench decode it:
            # handle = r + 256 g + 65536 b, white where nothing is seen.
            sim.setObjectInt32Param(sensor, sim.visionintparam_render_mode, sim.rendermode_colorcoded)
            sim.handleVisionSensor(sensor)
            rgb = np.array(client.image(sensor), dtype=np.int64)
            coded = rgb[..., 0] + 256 * rgb[..., 1] + 65536 * rgb[..., 2]
            coded[coded == 0xFFFFFF] = -1
            differ = np.argwhere(coded != seen)
            assert len(differ) == 0, (
                f"colour-coded image and mask differ at {len(differ)} pixels, first (row, col) "
                f"{differ[0].tolist()}: colour {coded[tuple(differ[0])]}, mask {seen[tuple(differ[0])]}"
            )
        handles = {"Floor": sim.getObject("/Floor")}
        for box in scene.boxes:
            handles[box.name] = sim.getObject("/" + box.name)
        # Every URDF link is a shape aliased by the link name, below the model base
        # aliased by the [[robot]] name (docs/scene-format.md, "URDF import").
        base = sim.getObject("/robot")
        for h in sim.getObjectsInTree(base, sim.object_shape_type):
            handles["link:" + sim.getObjectAlias(h)] = h
    assert depth.shape == (HEIGHT, WIDTH)
    return GantryView(depth, seen, handles)


@dataclass
class PyBulletView:
    depth: np.ndarray  # (HEIGHT, WIDTH) float64, metres, top row first
    seg: np.ndarray  # (HEIGHT, WIDTH) int: objectUniqueId + ((linkIndex + 1) << 24), -1 for nothing
    labels: dict[int, str]  # segmentation value -> "link:NAME", "Floor" or a box name


def pybullet_world(scene: Scene, cid: int) -> dict[int, str]:
    """Builds the scene in PyBullet client ``cid``: the robot (fixed base at the origin, the
    scene's joint angles), the floor and the boxes. Returns the segmentation labels:
    segmentation value -> "link:NAME", "Floor" or a box name."""
    kw = {"physicsClientId": cid}
    labels: dict[int, str] = {}
    body = pb.loadURDF(str(scene.robot.path), [0, 0, 0], [0, 0, 0, 1], useFixedBase=True, **kw)
    labels[body] = "link:" + pb.getBodyInfo(body, **kw)[0].decode()  # the base link: index -1
    by_name = {}
    for j in range(pb.getNumJoints(body, **kw)):
        info = pb.getJointInfo(body, j, **kw)  # joint j's child link is link j
        by_name[info[1].decode()] = j
        labels[body + ((j + 1) << 24)] = "link:" + info[12].decode()
    for name, value in scene.joints.items():
        pb.resetJointState(body, by_name[name], value, **kw)

    def box(half, pos, yaw_deg=0.0) -> int:
        col = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, **kw)
        vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=half, **kw)
        orn = pb.getQuaternionFromEuler([0, 0, math.radians(yaw_deg)])
        return pb.createMultiBody(0, col, vis, pos, orn, **kw)

    labels[box([FLOOR_SIZE[0] / 2, FLOOR_SIZE[1] / 2, 0.05], [0, 0, -0.05])] = "Floor"
    for b in scene.boxes:
        labels[box([s / 2 for s in b.size], list(b.position), b.yaw_deg)] = b.name
    return labels


def pybullet_matrices(cam: Camera, *, shift: bool = True) -> tuple[list[float], list[float]]:
    """PyBullet's view and projection matrices for ``cam`` (``shift``: sample pixel centres)."""
    view = pb.computeViewMatrix(list(cam.eye), list(cam.target), list(cam.up))
    proj = pb.computeProjectionMatrixFOV(vertical_fov_deg(cam.width, cam.height), cam.width / cam.height, NEAR, FAR)
    return view, (half_pixel_shift(proj, cam.width, cam.height) if shift else list(proj))


def render_pybullet(scene: Scene, *, shift: bool = True) -> PyBulletView:
    """PyBullet's TinyRenderer view of the scene (``shift``: sample at pixel centres)."""
    cid = pb.connect(pb.DIRECT)
    try:
        labels = pybullet_world(scene, cid)
        view, proj = pybullet_matrices(scene.camera, shift=shift)
        _, _, _, zbuf, seg = pb.getCameraImage(
            WIDTH, HEIGHT, view, proj, renderer=pb.ER_TINY_RENDERER,
            flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX, physicsClientId=cid,
        )
    finally:
        pb.disconnect(cid)
    depth = pybullet_depth_metres(np.reshape(zbuf, (HEIGHT, WIDTH)))
    return PyBulletView(depth, np.reshape(np.asarray(seg), (HEIGHT, WIDTH)), labels)


# ---------------------------------------------------------------------------------------
# Comparison


def neighbourhood_differs(img: np.ndarray, differs) -> np.ndarray:
    """True where ``differs(img[pixel], img[neighbour])`` for any of the 8 neighbours
    (neighbours outside the image do not count)."""
    h, w = img.shape
    out = np.zeros((h, w), dtype=bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dx == 0 and dy == 0:
                continue
            ys, yd = slice(max(dy, 0), h + min(dy, 0)), slice(max(-dy, 0), h + min(-dy, 0))
            xs, xd = slice(max(dx, 0), w + min(dx, 0)), slice(max(-dx, 0), w + min(-dx, 0))
            out[yd, xd] |= differs(img[yd, xd], img[ys, xs])
    return out


def edge_pixels(depths: list[np.ndarray], labels: list[np.ndarray]) -> np.ndarray:
    """Pixels with a depth jump > EDGE_JUMP or another object in their 3 x 3 neighbourhood,
    in any of the images."""
    edges = np.zeros(depths[0].shape, dtype=bool)
    for d in depths:
        edges |= neighbourhood_differs(d, lambda a, b: np.abs(a - b) > EDGE_JUMP * np.minimum(a, b))
    for lab in labels:
        edges |= neighbourhood_differs(lab, lambda a, b: a != b)
    return edges


def describe_failures(bad: np.ndarray, rows: list[tuple[str, np.ndarray]], label_names: np.ndarray,
                      limit: int = 12) -> str:
    """Where ``bad`` pixels are: their bounding box, count per object, and the first
    ``limit`` with each image's value, so a failure says what went wrong and where."""
    ys, xs = np.nonzero(bad)
    if len(ys) == 0:
        return "no failing pixels"
    lines = [f"{len(ys)} failing pixels in rows {ys.min()}..{ys.max()}, columns {xs.min()}..{xs.max()} "
             "(row 0 at the top, column 0 at the left)"]
    names, counts = np.unique(label_names[bad], return_counts=True)
    order = np.argsort(-counts)
    lines.append("by object (PyBullet's label): " + ", ".join(f"{names[i]}: {counts[i]}" for i in order[:8]))
    for y, x in list(zip(ys, xs))[:limit]:
        values = ", ".join(f"{name} {show(img[y, x])}" for name, img in rows)
        lines.append(f"  (row {y}, col {x}) {label_names[y, x]}: {values}")
    return "\n".join(lines)


def show(v) -> str:
    return f"{float(v):.4f}" if isinstance(v, (float, np.floating)) else str(v)


def label_name_image(view: PyBulletView) -> np.ndarray:
    names = np.full(view.seg.shape, "nothing", dtype=object)
    for value, name in view.labels.items():
        names[view.seg == value] = name
    return names


# ---------------------------------------------------------------------------------------
# Tests


def test_scenes_are_three_public_robots():
    assert len({s.robot.rid for s in SCENE_LIST}) >= 3
    for scene in SCENE_BY_ID.values():
        assert scene.robot.path.is_file(), (
            f"{scene.robot.path} is missing (pip install -r tests/python/requirements.txt)"
        )
        check_configuration(scene)


def test_tinyrenderer_samples_pixel_corners():
    """Why the referee shifts PyBullet's projection by half a pixel.

    The floor's planar depth along a pixel's ray is known in closed form. Unshifted,
    PyBullet's floor pixels match that depth at the pixel's lower-left corner (column + 0,
    row + 1 counted from the top), not at its centre; shifted, they match the centre, which
    is also where ``test_depth_matches_tinyrenderer`` then requires gantry to agree.
    """
    scene = SCENE_BY_ID["kuka_iiwa"]
    rows, cols = np.mgrid[0:HEIGHT, 0:WIDTH]
    for shift, (row_offset, col_offset) in ((False, (1.0, 0.0)), (True, (0.5, 0.5))):
        view = render_pybullet(scene, shift=shift)
        floor = view.seg == next(v for v, n in view.labels.items() if n == "Floor")
        floor &= ~edge_pixels([view.depth], [view.seg])
        assert floor.sum() > 0.2 * floor.size
        expected = floor_depth(scene, rows, cols, row_offset, col_offset)
        err = np.abs(view.depth - expected)[floor] / expected[floor]
        assert np.quantile(err, 0.99) < 1e-3, (shift, float(np.quantile(err, 0.99)))


def test_gantry_floor_depth_is_analytic(tmp_path: Path):
    """gantry against no renderer at all: its floor pixels (by its own mask) have the
    closed-form planar depth of the plane z = 0 along the ray through each pixel's centre,
    which pins its pose, fov-across-the-larger-side, row order and depth conventions
    independently of PyBullet."""
    scene = SCENE_BY_ID["kuka_iiwa"]
    g = render_gantry(scene, tmp_path, mask=True)
    floor = (g.mask == g.handles["Floor"]) & ~edge_pixels([g.depth], [g.mask])
    assert floor.sum() > 0.2 * floor.size
    rows, cols = np.mgrid[0:HEIGHT, 0:WIDTH]
    expected = floor_depth(scene, rows, cols, 0.5, 0.5)
    rel = np.zeros(floor.shape)
    rel[floor] = np.abs(g.depth - expected)[floor] / expected[floor]
    worst = np.unravel_index(np.argmax(rel), rel.shape)
    print(f"gantry floor depth against the closed form: largest relative error {rel.max():.2e} "
          f"over {floor.sum()} pixels")
    assert rel.max() < 1e-4, (
        f"largest relative error {rel.max():.2e} at (row, col) {tuple(int(i) for i in worst)}: "
        f"gantry {g.depth[worst]:.5f} m, analytic {expected[worst]:.5f} m"
    )


def per_object_agreement(good: np.ndarray, compared: np.ndarray, names: np.ndarray) -> dict[str, tuple[float, int]]:
    """Each object's (agreeing fraction, compared pixels), objects by PyBullet's label."""
    out = {}
    for name in np.unique(names[compared]):
        m = compared & (names == name)
        out[str(name)] = (float(good[m].sum() / m.sum()), int(m.sum()))
    return out


def check_agreement(what: str, scene: Scene, good: np.ndarray, compared: np.ndarray, names: np.ndarray,
                    values: list[tuple[str, np.ndarray]]) -> None:
    """The assertions both comparisons share, with a report of where they failed.

    Over the whole image: MIN_AGREEMENT of the non-edge pixels agree (issue 30's
    criterion). Per object: every object with at least OBJECT_MIN_PIXELS compared pixels
    agrees on OBJECT_MIN_AGREEMENT of them, because a missing part of one small link is
    well under 1 % of the image and would pass the image-wide criterion alone.
    """
    fraction = (good & compared).sum() / compared.sum()
    objects = per_object_agreement(good, compared, names)
    robot_pixels = sum(n for name, (_, n) in objects.items() if name.startswith("link:"))
    summary = ", ".join(f"{name} {frac:.1%} of {n}" for name, (frac, n) in sorted(objects.items()))
    print(f"{scene.sid}: {what} agrees on {fraction:.4%} of {compared.sum()} non-edge pixels "
          f"({compared.mean():.1%} of the image; {robot_pixels} on the robot)\n  per object: {summary}")
    poor = {name: v for name, v in objects.items() if v[1] >= OBJECT_MIN_PIXELS and v[0] < OBJECT_MIN_AGREEMENT}
    assert fraction >= MIN_AGREEMENT and not poor, (
        f"{scene.sid}: {what} agrees on {fraction:.4%} of non-edge pixels (need {MIN_AGREEMENT:.0%}); "
        f"objects below {OBJECT_MIN_AGREEMENT:.0%}: "
        + (", ".join(f"{name} {frac:.1%} of {n}" for name, (frac, n) in poor.items()) or "none")
        + "\n" + describe_failures(compared & ~good, values, names)
    )
    assert compared.mean() >= MIN_COMPARED, f"only {compared.mean():.1%} of the image is away from edges"
    assert robot_pixels >= MIN_ROBOT_PIXELS, f"the robot covers only {robot_pixels} compared pixels"


@pytest.mark.parametrize("scene", SCENE_LIST, ids=lambda s: s.sid)
def test_depth_matches_tinyrenderer(scene: Scene, tmp_path: Path):
    g = render_gantry(scene, tmp_path)
    p = render_pybullet(scene)
    names = label_name_image(p)
    unknown = set(np.unique(p.seg).tolist()) - set(p.labels) - {-1}
    assert not unknown, f"PyBullet segmentation values without a label: {sorted(unknown)}"

    compared = ~edge_pixels([g.depth, p.depth], [p.seg])
    good = np.abs(g.depth - p.depth) <= DEPTH_TOL * p.depth
    check_agreement(f"depth within {DEPTH_TOL:.0%}", scene, good, compared, names,
                    [("gantry m", g.depth), ("pybullet m", p.depth)])


@pytest.mark.parametrize("scene", SCENE_LIST, ids=lambda s: s.sid)
def test_mask_matches_segmentation(scene: Scene, tmp_path: Path):
    """gantry's mask (``client.mask``: the handle of the shape seen, -1 for nothing) against
    PyBullet's segmentation buffer, objectUniqueId + ((linkIndex + 1) << 24) (link index
    -1 is the base link), each value mapped to the gantry handle of the same URDF link,
    floor or box. Edge pixels: a depth jump in either depth image, or another value in
    either label image, in the 3 x 3 neighbourhood."""
    g = render_gantry(scene, tmp_path, mask=True)
    p = render_pybullet(scene)
    names = label_name_image(p)
    assert g.mask.shape == (HEIGHT, WIDTH)
    missing = {n for n in p.labels.values()} - set(g.handles)
    assert not missing, f"{scene.sid}: no gantry shape for {sorted(missing)}"
    expected = np.full(p.seg.shape, -1, dtype=np.int64)
    for value, name in p.labels.items():
        expected[p.seg == value] = g.handles[name]

    compared = ~edge_pixels([g.depth, p.depth], [p.seg, g.mask])
    good = g.mask == expected
    handle_names = {h: n for n, h in g.handles.items()}
    seen = np.vectorize(lambda h: handle_names.get(int(h), f"handle {h}"))(g.mask)
    check_agreement("mask", scene, good, compared, names,
                    [("gantry sees", seen), ("gantry handle", g.mask), ("expected handle", expected)])
