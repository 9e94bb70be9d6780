"""Occupancy maps at metric scale: a free mask with a resolution and an origin, and its loaders.

An :class:`OccupancyMap` is a bool mask ``free`` ``(rows, cols)``, row 0 at the TOP of the picture (as in the
image file), pixels ``resolution`` metres wide, and the ``origin`` ``(x, y)`` in metres of the lower-left
corner of the lower-left pixel (the ROS convention). Its :meth:`~OccupancyMap.world` traces the pixel borders
into a :class:`~digslam.envs.sim.world.World` whose free space is exactly the free pixels, everything outside
the mask closed. Loaders:

* :func:`load_ros_map`: the ROS map file pair (the format of nav2's map_server and map_saver, written by
  slam_toolbox, gmapping, cartographer): a YAML file with ``image``, ``resolution`` (m/px), ``origin``
  ``[x, y, yaw]``, ``negate``, ``occupied_thresh``, ``free_thresh`` and an optional ``mode``, beside a PGM,
  PNG or BMP image. See :func:`load_ros_map` for the pixel rule.
* :func:`load_plan`: the ``.npz`` floor-plan format of ``envs/data/floorplans/README.md`` (``wall``,
  ``rooms``, ``pixels_per_metre``), the outside of the building closed (:func:`plan_outside`).
* :func:`load_mask`: a plain image (bright is free) or a ``.npy`` bool mask (True is free) with an explicit
  resolution. :func:`load_map` picks one of the three by the file's suffix.

Doors. Tracing pixel borders is exact: a gap of ``k`` free pixels is ``k * resolution`` metres wide in the
world, and no loader ever narrows a gap (the outside rule only removes free space that is not the building's
floor). A robot disc of radius ``r`` passes a gap wider than ``2 r`` (0.4 m for the default 0.2 m; the pymunk
collision disc adds the skin, 0.0375 m with the default settings, so 0.475 m). The passage test of
:func:`disc_reachable` (a disc centred on a pixel centre fits when the centre lies ``r + resolution / sqrt 2``
from every non-free pixel centre) opens gaps of at least 5 px at 0.1 m/px (0.5 m) and 9 px at 0.05 m/px (0.45
m: the unicycle passes it, the pymunk disc does not; ``Floorplan(clearance=0.24)`` matches the pymunk robot on
such maps). A narrower slit (0.4 m or less at 0.1 m/px) stays free in the map and in the world, but is closed
to the robot: the simulator decides passability by geometry. The doors of the shipped plans are 0.8-1.6 m.

Errors: bad input raises one ``ValueError`` line naming the file and the key, and saying what to do.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from digslam.envs.sim.tracing import mask_edges
from digslam.envs.sim.world import World

#: Keys every ROS map YAML file must have (``mode`` is optional: ``trinary`` by default).
ROS_KEYS: tuple[str, ...] = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")
#: ROS map modes (nav2 map_server).
ROS_MODES: tuple[str, ...] = ("trinary", "scale", "raw")
#: Width (m) of the widest entrance that :func:`plan_outside` seals in a building's outer wall.
SEAL_WIDTH = 2.4
MASK_SUFFIXES: tuple[str, ...] = (".pgm", ".png", ".bmp", ".npy")


@dataclass(frozen=True, eq=False)
class OccupancyMap:
    """A free mask at metric scale.

    Attributes:
        free: bool ``(rows, cols)``, True where free, row 0 at the TOP of the picture; stored as a read-only
            copy (the caller's array is never modified).
        resolution: Pixel side (m), > 0.
        origin: ``(x, y)`` (m) of the lower-left corner of the lower-left pixel.
        name: The map's name (file stem), for messages and provenance.
    """

    free: np.ndarray
    resolution: float
    origin: tuple[float, float] = (0.0, 0.0)
    name: str = "map"

    def __post_init__(self) -> None:
        free = np.array(self.free, dtype=bool, copy=True)
        if free.ndim != 2 or min(free.shape) == 0:
            raise ValueError(f"{self.name}: free must be a non-empty 2-D mask, got shape {free.shape}")
        res = float(self.resolution)
        if not (math.isfinite(res) and res > 0):
            raise ValueError(f"{self.name}: resolution must be a finite number > 0 (m/px), got {res!r}")
        ox, oy = (float(v) for v in self.origin)
        if not (math.isfinite(ox) and math.isfinite(oy)):
            raise ValueError(f"{self.name}: origin must be finite (x, y) in metres, got {self.origin!r}")
        free.flags.writeable = False
        object.__setattr__(self, "free", free)
        object.__setattr__(self, "resolution", res)
        object.__setattr__(self, "origin", (ox, oy))

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, cols)``."""
        return (int(self.free.shape[0]), int(self.free.shape[1]))

    @property
    def frame(self) -> tuple[float, float, float, float]:
        """``(x0, y0, x1, y1)`` (m): the map's extent."""
        (ox, oy), (rows, cols) = self.origin, self.shape
        return (ox, oy, ox + cols * self.resolution, oy + rows * self.resolution)

    @property
    def free_area(self) -> float:
        """Free area (m²)."""
        return float(np.count_nonzero(self.free)) * self.resolution**2

    def world(self) -> World:
        """The :class:`~digslam.envs.sim.world.World` of this map in its own frame: the traced pixel borders
        (collinear runs merged), everything outside the mask closed."""
        return World.from_edges(self.frame, mask_edges(self.free[::-1], self.frame), self.name)


def disc_reachable(free: np.ndarray, resolution: float, clearance: float) -> np.ndarray:
    """The pixels (same layout as ``free``) of the largest 8-connected region of pixel centres where a disc of
    radius ``clearance`` fits in the free pixels (outside the mask closed): a centre counts when it lies at
    least ``clearance + resolution / sqrt(2)`` from every non-free pixel centre (conservative). All False when
    the disc fits nowhere."""
    from scipy import ndimage

    pad = np.pad(np.asarray(free, dtype=bool), 1)
    room = ndimage.distance_transform_edt(pad)[1:-1, 1:-1] * resolution
    ok = room - resolution / math.sqrt(2.0) >= clearance
    lab, n = ndimage.label(ok, structure=np.ones((3, 3), dtype=bool))
    if n == 0:
        return np.zeros_like(ok)
    return np.asarray(lab == 1 + int(np.argmax(np.bincount(lab.ravel())[1:])))


def plan_outside(wall: np.ndarray, rooms: np.ndarray | None, seal: int) -> np.ndarray:
    """The free pixels of a plan that are not the building's floor: the outside, and closed cavities.

    The walls are closed by a square of side ``seal + 1`` pixels (a morphological closing, padded so that
    the image border is open), which seals every gap of up to ``seal`` pixels, entrances included. The
    outside is the free space 4-connected to the image border in what remains open. A cavity is a 4-connected
    free component that the closing filled entirely and that holds no labelled room pixel (hollow pillars,
    wall cavities, the corners the closing filled outside the outer wall). ``rooms`` pixels > 0 are never
    returned; ``rooms == 0`` is not read as outside (doorways and corridors are unlabelled)."""
    from scipy import ndimage

    wall = np.asarray(wall, dtype=bool)
    p = seal // 2 + 2
    padded = np.pad(wall, p).astype(np.uint8)
    closed = ndimage.minimum_filter(ndimage.maximum_filter(padded, size=seal + 1), size=seal + 1)
    lab, _ = ndimage.label(closed == 0)
    outside = np.isin(lab, np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]])))
    outside &= lab > 0
    outside = outside[p:-p, p:-p]
    closed_in = closed[p:-p, p:-p].astype(bool)
    free = ~wall
    labelled = np.zeros(wall.shape, dtype=bool) if rooms is None else np.asarray(rooms) > 0
    rest, n = ndimage.label(free & ~outside)
    if n:
        open_px = np.bincount(rest.ravel(), weights=(~closed_in | labelled).ravel(), minlength=n + 1)
        cavity = open_px == 0
        cavity[0] = False
        outside |= cavity[rest]
    return outside & free & ~labelled


# --- loaders ---------------------------------------------------------------------------------------------


def _fail(path: Path, key: str, what: str) -> ValueError:
    return ValueError(" ".join(f"{path}: {key}: {what}".split()))


def _read_pgm(path: Path) -> np.ndarray:
    """Grey values 0..255 (float, ``(rows, cols)``) of a PGM file, P2 (plain) or P5 (binary, 8 or 16 bit);
    ``#`` comments allowed in the header (and, in P2, anywhere)."""
    data = path.read_bytes()
    tokens: list[bytes] = []
    i = 0
    while len(tokens) < 4:
        while i < len(data) and data[i : i + 1].isspace():
            i += 1
        if data[i : i + 1] == b"#":
            i = data.find(b"\n", i) + 1 or len(data)
            continue
        j = i
        while j < len(data) and not data[j : j + 1].isspace() and data[j : j + 1] != b"#":
            j += 1
        if j == i:
            raise ValueError("truncated PGM header")
        tokens.append(data[i:j])
        i = j
    magic, w, h, maxval = tokens[0], int(tokens[1]), int(tokens[2]), int(tokens[3])
    if magic not in (b"P2", b"P5") or w <= 0 or h <= 0 or not 0 < maxval < 65536:
        raise ValueError(f"not a P2/P5 PGM header ({magic!r}, {w} x {h}, maxval {maxval})")
    if magic == b"P5":
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype(np.uint8)
        raw = np.frombuffer(data, dtype=dtype, count=w * h, offset=i + 1)
    else:
        body = b" ".join(line.split(b"#", 1)[0] for line in data[i:].splitlines())
        raw = np.array(body.split()[: w * h], dtype=np.int64)
        if raw.size != w * h:
            raise ValueError(f"{raw.size} pixel values for {w} x {h}")
    return raw.reshape(h, w).astype(np.float64) * (255.0 / maxval)


def _read_image(path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    """Grey values 0..255 ``(rows, cols)`` (mean of the colour channels) and alpha 0..255 (None if opaque);
    ValueError with the reason (without the file name) when the image cannot be read."""
    try:
        if path.read_bytes()[:2] in (b"P2", b"P5"):
            return _read_pgm(path), None
        import pygame  # only for PNG/BMP images

        surf = pygame.image.load(str(path))
        grey = pygame.surfarray.array3d(surf).astype(np.float64).mean(axis=2).T
        alpha = pygame.surfarray.array_alpha(surf).T if surf.get_flags() & pygame.SRCALPHA else None
    except Exception as e:  # OSError, ValueError from the PGM reader, pygame.error (pygame may be absent)
        raise ValueError(f"cannot read {path.name} ({e}); give an 8-bit PGM (P2/P5), PNG or BMP") from None
    return grey, alpha


def _number(path: Path, doc: Mapping[str, object], key: str) -> float:
    v = doc[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(float(v)):
        raise _fail(path, key, f"must be a finite number, got {v!r}")
    return float(v)


def load_ros_map(yaml_path: str | Path) -> OccupancyMap:
    """The map of a ROS map YAML file and its image (nav2 map_server format).

    Keys: ``image`` (a path; relative to the YAML file's folder), ``resolution`` (m/px, > 0), ``origin``
    ``[x, y, yaw]`` (m, rad: the lower-left pixel's lower-left corner; a non-zero ``yaw`` is refused),
    ``negate`` (0/1), ``occupied_thresh`` and ``free_thresh`` (in [0, 1], ``free < occupied``), optional
    ``mode`` (``trinary``, the default, ``scale`` or ``raw``). The YAML is read with ``yaml.safe_load``.

    Pixels, as nav2 reads them: ``v`` is the grey value 0..255 (mean of the colour channels; alpha ignored
    but in ``scale`` mode, where a pixel that is not opaque is unknown). Trinary and scale: the occupancy is
    ``p = (255 - v) / 255`` (``v / 255`` when ``negate``); occupied when ``p > occupied_thresh``, free when
    ``p < free_thresh``, unknown between. Raw: ``v`` itself is the occupancy in percent (0..100, else
    unknown; ``negate`` and the thresholds unused); free iff ``v == 0``. Unknown counts as obstacle.
    """
    path = Path(yaml_path)
    try:
        import yaml  # PyYAML: only for ROS maps

        doc = yaml.safe_load(path.read_text())
    except (OSError, UnicodeDecodeError) as e:
        raise _fail(path, "yaml", f"cannot read the file ({e.__class__.__name__}: {e})") from None
    except Exception as e:  # yaml.YAMLError
        raise _fail(path, "yaml", f"not a valid YAML map file ({e})") from None
    if not isinstance(doc, Mapping):
        raise _fail(path, "yaml", f"must be a mapping of the keys {', '.join(ROS_KEYS)}, got {doc!r:.60}")
    for key in ROS_KEYS:
        if key not in doc:
            raise _fail(path, key, f"missing key; a ROS map YAML file needs {', '.join(ROS_KEYS)}")
    res = _number(path, doc, "resolution")
    if res <= 0:
        raise _fail(path, "resolution", f"must be > 0 (metres per pixel), got {doc['resolution']!r}")
    origin = doc["origin"]
    if not isinstance(origin, Sequence) or isinstance(origin, str) or len(origin) not in (2, 3):
        raise _fail(path, "origin", f"must be [x, y, yaw], got {origin!r}")
    if not all(isinstance(v, (int, float)) and math.isfinite(float(v)) for v in origin):
        raise _fail(path, "origin", f"must be finite numbers [x, y, yaw], got {origin!r}")
    if len(origin) == 3 and float(origin[2]) != 0.0:
        raise _fail(path, "origin", f"yaw {origin[2]!r} != 0: a rotated map is refused; rotate the image")
    negate = doc["negate"]
    if negate not in (0, 1):  # True and False included
        raise _fail(path, "negate", f"must be 0 or 1, got {negate!r}")
    occ_t, free_t = _number(path, doc, "occupied_thresh"), _number(path, doc, "free_thresh")
    for key, v in (("occupied_thresh", occ_t), ("free_thresh", free_t)):
        if not 0.0 <= v <= 1.0:
            raise _fail(path, key, f"must be in [0, 1], got {v!r}")
    if free_t >= occ_t:
        raise _fail(path, "free_thresh", f"must be < occupied_thresh ({occ_t!r}), got {free_t!r}")
    mode = doc.get("mode", "trinary")
    if mode not in ROS_MODES:
        raise _fail(path, "mode", f"must be one of {', '.join(ROS_MODES)}, got {mode!r}")
    if not isinstance(doc["image"], str) or not doc["image"]:
        raise _fail(path, "image", f"must be a file name, got {doc['image']!r}")
    image = Path(doc["image"]) if Path(doc["image"]).is_absolute() else path.parent / doc["image"]
    if not image.is_file():
        raise _fail(path, "image", f"the image file {str(image)!r} does not exist; fix the path")
    try:
        grey, alpha = _read_image(image)
    except ValueError as e:
        raise _fail(path, "image", str(e)) from None
    if mode == "raw":
        free = np.rint(grey) == 0
    else:
        p = grey / 255.0 if negate else (255.0 - grey) / 255.0
        free = p < free_t
        if mode == "scale" and alpha is not None:
            free &= alpha == 255
    if not free.any():
        raise _fail(path, "image", f"{image.name} has no free pixel (mode {mode}, negate {int(negate)}, "
                    f"free_thresh {free_t}); check negate and the thresholds")  # fmt: skip
    return OccupancyMap(free, res, (float(origin[0]), float(origin[1])), path.stem)


def load_plan(npz_path: str | Path, seal: float = SEAL_WIDTH) -> OccupancyMap:
    """The map of a floor plan ``.npz`` (``envs/data/floorplans/README.md``): ``wall`` bool ``(rows, cols)``
    (row 0 at the top), ``pixels_per_metre`` (> 0), optional ``rooms`` (uint8 labels, > 0 in a labelled
    room). Free is every pixel that is not a wall, but for :func:`plan_outside` (entrances of up to ``seal``
    metres sealed): the outside of the building and closed cavities are obstacle. Origin ``(0, 0)``."""
    path = Path(npz_path)
    try:
        if path.read_bytes()[:2] != b"PK":
            raise ValueError("not a .npz (zip) archive")
        with np.load(path, allow_pickle=False) as z:
            data = {k: np.asarray(z[k]) for k in z.files}
    except (OSError, ValueError) as e:
        raise _fail(
            path, "npz", f"cannot read the plan ({e}); give a .npz of wall, pixels_per_metre"
        ) from None
    for key in ("wall", "pixels_per_metre"):
        if key not in data:
            raise _fail(path, key, "missing key; a plan .npz needs wall, pixels_per_metre (and rooms)")
    wall = data["wall"]
    if wall.ndim != 2 or min(wall.shape) == 0 or not (wall.dtype == bool or np.isin(wall, (0, 1)).all()):
        raise _fail(path, "wall", f"must be a 2-D bool mask, got {wall.dtype} {wall.shape}")
    ppm = data["pixels_per_metre"]
    number = ppm.size == 1 and np.issubdtype(ppm.dtype, np.number)
    if not (number and math.isfinite(ppm.item()) and ppm.item() > 0):
        raise _fail(path, "pixels_per_metre", f"must be one number > 0, got {ppm!r}")
    rooms = data.get("rooms")
    if rooms is not None and rooms.shape != wall.shape:
        raise _fail(path, "rooms", f"must have the shape of wall {wall.shape}, got {rooms.shape}")
    wall = wall.astype(bool)
    res = 1.0 / float(ppm.item())
    free = ~wall & ~plan_outside(wall, rooms, int(round(seal / res)))
    if not free.any():
        raise _fail(path, "wall", "the plan has no free pixel inside the building")
    return OccupancyMap(free, res, (0.0, 0.0), path.stem)


def load_mask(path: str | Path, resolution: float, origin: tuple[float, float] = (0.0, 0.0)) -> OccupancyMap:
    """The map of a plain image (PGM, PNG, BMP: grey > 127.5 is free) or a ``.npy`` mask (bool, or 0/1:
    True/1 is free), row 0 at the top, with ``resolution`` (m/px) and ``origin`` given by the caller."""
    p = Path(path)
    if not (isinstance(resolution, (int, float)) and math.isfinite(resolution) and resolution > 0):
        raise _fail(p, "resolution", f"must be a number > 0 (metres per pixel), got {resolution!r}")
    if p.suffix.lower() == ".npy":
        if not p.is_file():
            raise _fail(p, "path", "the mask file does not exist; fix the path")
        try:
            arr = np.load(p, allow_pickle=False)
        except (OSError, ValueError) as e:
            raise _fail(p, "path", f"cannot read the .npy mask ({e})") from None
        if arr.ndim != 2 or not (arr.dtype == bool or np.isin(arr, (0, 1)).all()):
            raise _fail(p, "path", f"must hold a 2-D bool mask (True is free), got {arr.dtype} {arr.shape}")
        free = arr.astype(bool)
    else:
        if not p.is_file():
            raise _fail(p, "path", "the image file does not exist; fix the path")
        try:
            free = _read_image(p)[0] > 127.5
        except ValueError as e:
            raise _fail(p, "path", str(e)) from None
    if not free.any():
        raise _fail(p, "path", "the mask has no free pixel (bright or True is free)")
    return OccupancyMap(free, float(resolution), origin, p.stem)


def load_map(path: str | Path, resolution: float | None = None) -> OccupancyMap:
    """:func:`load_ros_map` for ``.yaml``/``.yml``, :func:`load_plan` for ``.npz`` (both carry their scale:
    ``resolution`` must be None), :func:`load_mask` for ``.pgm``/``.png``/``.bmp``/``.npy`` (``resolution``
    required)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix in (".yaml", ".yml", ".npz"):
        if resolution is not None:
            raise _fail(p, "resolution", "the file gives its own scale; leave resolution=None")
        if not p.is_file():
            raise _fail(p, "path", "the map file does not exist; fix the path")
        return load_plan(p) if suffix == ".npz" else load_ros_map(p)
    if suffix in MASK_SUFFIXES:
        if resolution is None:
            raise _fail(p, "resolution", "required for an image or .npy map (metres per pixel)")
        return load_mask(p, resolution)
    raise _fail(p, "path", f"unknown map suffix {suffix!r}: use .yaml/.yml, .npz, {', '.join(MASK_SUFFIXES)}")


__all__ = [
    "MASK_SUFFIXES",
    "ROS_KEYS",
    "ROS_MODES",
    "SEAL_WIDTH",
    "OccupancyMap",
    "disc_reachable",
    "load_map",
    "load_mask",
    "load_plan",
    "load_ros_map",
    "plan_outside",
]
