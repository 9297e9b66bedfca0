#!/usr/bin/env python3
"""Independent reference for a lit Quake BSP: each drawn luxel's mean irradiance, by Monte Carlo
with Mitsuba 3's ray tracer, compared with the lightmap the BSP holds.

Requires: pip install mitsuba numpy   (Mitsuba 3 with its llvm_ad_rgb CPU variant; Dr.Jit comes
with it and needs the system's libLLVM)

Usage: reference.py LIT.bsp [--every N] [--max-luxels M] [--seed S] [--bounce [N]]
                            [--palette palette.lmp] [--json OUT.json] [--faces-csv OUT.csv]
                            [--no-cache]

It reads the BSP with its own reader (BSP29, BSP2 and 2PSB: faces, planes, texinfo, miptex,
models, entities, the lighting lump and a `.lit` file beside the BSP), builds the world's and
the visible brush models' triangles into a Mitsuba scene, and for every drawn luxel of every
judged face estimates the mean irradiance over the luxel's footprint: the 16x16 texel square
around its sample point clipped to the face polygon. Light is physical: point lights with
inverse-square falloff and Lambert's cosine law, spotlight cones, a sun (a directional light
that arrives through sky faces), sky domes (uniform radiance through sky faces, upper and lower
hemisphere) and, with --bounce, the diffuse interreflection between surfaces whose albedo is
their texture's mean colour. Visibility is exact: every shadow ray is traced, and passes the holes
(palette index 255) of fence textures, whose names begin with `{`, as engines draw them. The conversion
from Quake's light units is one constant per light kind (see README.md beside this file).

The last line it prints is `rmse R over N drawn luxels; noise S`: R is the area-weighted RMS
difference, in 8-bit light levels, between the lightmap's style-0 bytes (per channel of the
`.lit` when there is one) and the reference clamped to what a lightmap can hold; S is the
reference's own Monte Carlo standard error, RMS over the same luxels, from independent batches.
It shares no code with Slipgate's light.
"""
import argparse
import hashlib
import json
import math
import os
import struct
import sys
import time

import numpy as np

# --- Conversion from Quake light units (README.md: how they were derived and checked) ---------
# Both tools scale every light by the worldspawn range scale (0.5 by default) on the way into
# the lightmap, and inverse-square lights are normalised to their `light` value at 128 units.
RANGE_SCALE = 0.5
INVERSE_SQUARE_DISTANCE = 128.0
# A point light of brightness `light` has radiant intensity POINT_INTENSITY * light (per channel,
# times colour / 255): a surface facing it at distance d gets POINT_INTENSITY * light / d^2.
POINT_INTENSITY = RANGE_SCALE * INVERSE_SQUARE_DISTANCE**2
# A sun of brightness `_sunlight` gives SUN_IRRADIANCE * _sunlight on a surface facing it.
SUN_IRRADIANCE = RANGE_SCALE
# Dome lights (`_sunlight2`, `_sunlight3`) are given as the light an open floor receives from the
# dome's suns, which ericw-tools lays out in four rings of 16 (elevations 9, 27, 45 and 63
# degrees) and one at the zenith, each of brightness 1/65 of the key. A uniform sky of radiance L
# gives an open floor pi * L, so L = RANGE_SCALE * value * DOME_FLOOR_FACTOR / pi.
DOME_RINGS_DEG = (9.0, 27.0, 45.0, 63.0)
DOME_RING_SUNS = 16
DOME_SUNS = len(DOME_RINGS_DEG) * DOME_RING_SUNS + 1
DOME_FLOOR_FACTOR = (
    DOME_RING_SUNS * sum(math.sin(math.radians(e)) for e in DOME_RINGS_DEG) + 1.0
) / DOME_SUNS
DOME_RADIANCE = RANGE_SCALE * DOME_FLOOR_FACTOR / math.pi

# --- Quake's conventions -----------------------------------------------------------------------
DEFAULT_LIGHT = 300.0
DEFAULT_SPOT_ANGLE = 40.0
DEFAULT_SUN_MANGLE = (0.0, -90.0, 0.0)
LUXEL = 16.0
# Brush models that move: their lightmap holds one position's light and any shadow they cast
# would be wrong in every other, so they are neither in the scene nor judged.
MOVING_MODEL_CLASSES = ("func_door", "func_plat", "func_train", "func_button", "func_rotat", "rotate_",
                        "func_bob", "func_movewall")
TEX_SPECIAL = 1
FULLBRIGHT_FIRST = 224
LIGHTMAP_MAX = 255.0
MAX_STYLES = 4

# --- The estimator -----------------------------------------------------------------------------
BATCHES = 4  # independent batches per luxel: their spread gives the noise
GRID = 2  # a batch's samples in a whole luxel: GRID x GRID jittered
EDGE_GRID = 4  # a batch's candidate samples in a luxel cut by the polygon's edge
FINE_GRID = 8  # a batch's samples in a luxel estimated again because its batches disagreed
FINE_NOISE = 0.5  # levels: a luxel whose first estimate's standard error exceeds this is redone
SKY_RAYS = 16  # cosine-weighted sky rays per sample point (256 per luxel)
BOUNCE_RAYS = 16  # cosine-weighted gather rays per sample point for interreflection
ROULETTE_LEVEL = 0.25  # unshadowed contributions below this many levels are traced by chance
RAY_OFFSET = 0.1  # shadow rays start this far off the surface
EXTENT_TOLERANCE = 0.01  # texture units: a face extreme this close to a luxel boundary is uncertain
MIN_FOOTPRINT = 1e-3  # texture units^2: a luxel square touching the polygon less is not drawn
DEFAULT_MAX_LUXELS = 40000  # judged luxels the automatic subset aims at
RAY_CHUNK = 1 << 21
SKY_DISTANCE = 65536.0
BOUNCE_ITERATION_LIMIT = 32
BOUNCE_CONVERGED = 0.05  # levels: interreflection stops when no luxel changes more
CACHE_VERSION = 4
FENCE_TRANSPARENT = 255  # palette index a `{` texture shows as a hole (light passes there)
FENCE_LAYERS = 16  # holes a ray passes through at most before it counts as blocked
FENCE_STEP = 1e-3  # units: a ray through a hole goes on from this far past it


class BspError(Exception):
    pass


# ================================================================================================
# BSP reader
# ================================================================================================
LUMP_ENTITIES, LUMP_PLANES, LUMP_TEXTURES, LUMP_VERTICES = 0, 1, 2, 3
LUMP_TEXINFO, LUMP_FACES, LUMP_LIGHTING = 6, 7, 8
LUMP_EDGES, LUMP_SURFEDGES, LUMP_MODELS = 12, 13, 14
LUMP_COUNT = 15


class Bsp:
    def __init__(self, path):
        self.path = path
        with open(path, "rb") as f:
            data = f.read()
        if len(data) < 4 + 8 * LUMP_COUNT:
            raise BspError(f"{path}: too short for a BSP header")
        magic = data[:4]
        if magic in (b"BSP2", b"2PSB"):
            self.kind = magic.decode()
        elif struct.unpack_from("<i", data, 0)[0] == 29:
            self.kind = "BSP29"
        else:
            raise BspError(f"{path}: not a BSP29, BSP2 or 2PSB file")
        lumps = []
        for i in range(LUMP_COUNT):
            ofs, length = struct.unpack_from("<ii", data, 4 + 8 * i)
            if ofs < 0 or length < 0 or ofs + length > len(data):
                raise BspError(f"{path}: lump {i} lies outside the file")
            lumps.append(data[ofs : ofs + length])
        self.lumps = lumps
        self.entities = parse_entities(lumps[LUMP_ENTITIES].split(b"\0")[0].decode("latin-1"))
        planes = np.frombuffer(lumps[LUMP_PLANES], dtype=np.dtype([("n", "<f4", 3), ("d", "<f4"), ("t", "<i4")]))
        self.plane_normal = planes["n"].astype(np.float64)
        self.plane_dist = planes["d"].astype(np.float64)
        self.vertices = np.frombuffer(lumps[LUMP_VERTICES], dtype="<f4").reshape(-1, 3).astype(np.float64)
        ti = np.frombuffer(lumps[LUMP_TEXINFO], dtype=np.dtype([("v", "<f4", (2, 4)), ("m", "<i4"), ("f", "<i4")]))
        self.tex_vecs = ti["v"].astype(np.float64)
        self.tex_miptex = ti["m"]
        self.tex_flags = ti["f"]
        if self.kind == "BSP29":
            fdt = np.dtype([("plane", "<u2"), ("side", "<u2"), ("firstedge", "<i4"), ("numedges", "<u2"),
                            ("texinfo", "<u2"), ("styles", "u1", 4), ("lightofs", "<i4")])
            edt = np.dtype([("v", "<u2", 2)])
        elif self.kind == "BSP2":
            fdt = np.dtype([("plane", "<i4"), ("side", "<i4"), ("firstedge", "<i4"), ("numedges", "<i4"),
                            ("texinfo", "<i4"), ("styles", "u1", 4), ("lightofs", "<i4")])
            edt = np.dtype([("v", "<u4", 2)])
        else:  # 2PSB: BSP2's sizes for faces and edges, older node layout (not read here)
            fdt = np.dtype([("plane", "<i4"), ("side", "<i4"), ("firstedge", "<i4"), ("numedges", "<i4"),
                            ("texinfo", "<i4"), ("styles", "u1", 4), ("lightofs", "<i4")])
            edt = np.dtype([("v", "<u4", 2)])
        self.faces = np.frombuffer(lumps[LUMP_FACES], dtype=fdt)
        self.edges = np.frombuffer(lumps[LUMP_EDGES], dtype=edt)["v"].astype(np.int64)
        self.surfedges = np.frombuffer(lumps[LUMP_SURFEDGES], dtype="<i4").astype(np.int64)
        mdt = np.dtype([("mins", "<f4", 3), ("maxs", "<f4", 3), ("origin", "<f4", 3), ("head", "<i4", 4),
                        ("visleafs", "<i4"), ("firstface", "<i4"), ("numfaces", "<i4")])
        self.models = np.frombuffer(lumps[LUMP_MODELS], dtype=mdt)
        self.lighting = np.frombuffer(lumps[LUMP_LIGHTING], dtype=np.uint8)
        self.lit = self._read_lit(path)
        self._read_textures(lumps[LUMP_TEXTURES])
        self._check_indices()

    def _read_lit(self, path):
        lit_path = os.path.splitext(path)[0] + ".lit"
        if not os.path.exists(lit_path):
            return None
        with open(lit_path, "rb") as f:
            data = f.read()
        if data[:4] != b"QLIT" or struct.unpack_from("<i", data, 4)[0] != 1:
            raise BspError(f"{lit_path}: not a version 1 .lit file")
        lit = np.frombuffer(data[8:], dtype=np.uint8)
        if len(lit) != 3 * len(self.lighting):
            raise BspError(f"{lit_path}: {len(lit)} bytes of colour for {len(self.lighting)} luxels")
        return lit.reshape(-1, 3)

    def _read_textures(self, lump):
        self.tex_names, self.tex_pixels, self.tex_sizes = [], [], []
        if len(lump) < 4:
            return
        count = struct.unpack_from("<i", lump, 0)[0]
        if count < 0 or 4 + 4 * count > len(lump):
            raise BspError(f"{self.path}: texture lump's count {count} is out of range")
        offsets = struct.unpack_from(f"<{count}i", lump, 4)
        for ofs in offsets:
            if ofs < 0 or ofs + 40 > len(lump):
                self.tex_names.append("")
                self.tex_pixels.append(None)
                self.tex_sizes.append((0, 0))
                continue
            name = lump[ofs : ofs + 16].split(b"\0")[0].decode("latin-1").lower()
            width, height, mip0 = struct.unpack_from("<IIi", lump, ofs + 16)
            pixels = None
            if 0 < mip0 and width * height > 0 and ofs + mip0 + width * height <= len(lump):
                pixels = np.frombuffer(lump, dtype=np.uint8, count=width * height, offset=ofs + mip0)
            self.tex_names.append(name)
            self.tex_pixels.append(pixels)
            self.tex_sizes.append((width, height))

    def _check_indices(self):
        f = self.faces
        if len(f) == 0:
            return
        if f["plane"].max() >= len(self.plane_normal) or f["texinfo"].max() >= len(self.tex_vecs):
            raise BspError(f"{self.path}: a face names a plane or texinfo that does not exist")
        last = f["firstedge"].astype(np.int64) + f["numedges"]
        if f["firstedge"].min() < 0 or last.max() > len(self.surfedges):
            raise BspError(f"{self.path}: a face's edges lie outside the surfedge lump")
        if np.abs(self.surfedges).max(initial=0) >= len(self.edges):
            raise BspError(f"{self.path}: a surfedge names an edge that does not exist")
        if self.edges.size and self.edges.max() >= len(self.vertices):
            raise BspError(f"{self.path}: an edge names a vertex that does not exist")

    def face_vertices(self, face):
        f = self.faces[face]
        se = self.surfedges[f["firstedge"] : f["firstedge"] + f["numedges"]]
        idx = np.where(se >= 0, self.edges[np.abs(se), 0], self.edges[np.abs(se), 1])
        return self.vertices[idx]

    def texture_name(self, face):
        m = self.tex_miptex[self.faces[face]["texinfo"]]
        return self.tex_names[m] if 0 <= m < len(self.tex_names) else ""

    def geometry_digest(self):
        """A hash of the geometry and textures: what light leaves as it found it (every lump but
        the entities and the lighting, and the faces without their styles and lightmap offsets)."""
        h = hashlib.sha256()
        for i, lump in enumerate(self.lumps):
            if i in (LUMP_ENTITIES, LUMP_LIGHTING):
                continue
            if i == LUMP_FACES:
                faces = self.faces.copy()
                faces["styles"] = 0
                faces["lightofs"] = 0
                lump = faces.tobytes()
            h.update(struct.pack("<q", len(lump)))
            h.update(lump)
        return h.hexdigest()


def parse_entities(text):
    ents, cur, i, n = [], None, 0, len(text)
    while i < n:
        c = text[i]
        if c == "{":
            cur = {}
            i += 1
        elif c == "}":
            if cur is not None:
                ents.append(cur)
            cur = None
            i += 1
        elif c == '"':
            end = text.find('"', i + 1)
            if end < 0:
                break
            key = text[i + 1 : end]
            i = text.find('"', end + 1)
            if i < 0:
                break
            end = text.find('"', i + 1)
            if end < 0:
                break
            if cur is not None:
                cur[key] = text[i + 1 : end]
            i = end + 1
        else:
            i += 1
    return ents


def vector(value, default=(0.0, 0.0, 0.0)):
    try:
        parts = [float(x) for x in value.split()]
    except (ValueError, AttributeError):
        return np.array(default, dtype=np.float64)
    if len(parts) < 3:
        return np.array(default, dtype=np.float64)
    return np.array(parts[:3], dtype=np.float64)


def number(value, default):
    try:
        return float(value.split()[0])
    except (ValueError, AttributeError, IndexError):
        return default


def key(ent, *names, default=None):
    lower = {k.lower(): v for k, v in ent.items()}
    for name in names:
        if name in lower:
            return lower[name]
    return default


def colour(value):
    """A light colour per channel in 0..1 of full: `r g b` in 0..255, or in 0..1 when every
    component is at most 1."""
    if value is None:
        return np.ones(3)
    c = vector(value, (255.0, 255.0, 255.0))
    if np.all(c <= 1.0):
        c = c * 255.0
    return c / 255.0


def direction_from_mangle(m):
    yaw, pitch = math.radians(m[0]), math.radians(m[1])
    return np.array([math.cos(yaw) * math.cos(pitch), math.sin(yaw) * math.cos(pitch), math.sin(pitch)])


def load_palette(bsp_path, explicit):
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = [explicit] if explicit else []
    game = os.path.dirname(os.path.dirname(os.path.abspath(bsp_path)))
    candidates += [
        os.path.join(game, "gfx", "palette.lmp"),
        os.path.join(here, "..", "..", "..", "shared", "corpus", "palette", "palette.lmp"),
    ]
    for path in candidates:
        if path and os.path.exists(path):
            data = open(path, "rb").read()
            if len(data) >= 768:
                return np.frombuffer(data[:768], dtype=np.uint8).reshape(256, 3) / 255.0, path
    return None, None


# ================================================================================================
# The scene
# ================================================================================================
class Light:
    def __init__(self, origin, intensity, spot_dir=None, cos_outer=None, cos_inner=None):
        self.origin = origin
        self.intensity = intensity  # per channel, levels * units^2
        self.spot_dir = spot_dir
        self.cos_outer = cos_outer
        self.cos_inner = cos_inner


def style0_lights(entities):
    """Point and spot lights that light style 0, as the BSP's entities place them."""
    by_name = {}
    for e in entities:
        if "targetname" in e:
            by_name.setdefault(e["targetname"], e)
    lights = []
    for e in entities:
        cls = e.get("classname", "")
        if not cls.startswith("light"):
            continue
        if key(e, "_surface"):
            continue  # a surface-light template, not a light
        if any(number(key(e, k, default="0"), 0.0) != 0.0 for k in ("_sun", "_sunlight2", "_sunlight3")):
            continue
        style = int(number(e.get("style", "0"), 0.0))
        if style != 0 or e.get("targetname"):
            continue  # animated or switchable: not style 0
        value = number(e["light"], DEFAULT_LIGHT) if "light" in e else DEFAULT_LIGHT
        if value <= 0:
            continue
        origin = vector(e.get("origin", "0 0 0"))
        rgb = colour(key(e, "_color", "color"))
        spot_dir = None
        target = e.get("target")
        mangle = key(e, "mangle", "_mangle")
        if target and target in by_name:
            d = vector(by_name[target].get("origin", "0 0 0")) - origin
            if np.linalg.norm(d) > 0:
                spot_dir = d / np.linalg.norm(d)
        elif mangle is not None:
            spot_dir = direction_from_mangle(vector(mangle))
        light = Light(origin, POINT_INTENSITY * value * rgb)
        if spot_dir is not None:
            angle = number(e.get("angle", "0"), 0.0)
            if angle <= 0:
                angle = DEFAULT_SPOT_ANGLE
            soft = number(key(e, "_softangle", default="0"), 0.0)
            if soft <= 0 or soft > angle:
                soft = angle
            light.spot_dir = spot_dir
            light.cos_outer = math.cos(math.radians(angle / 2))
            light.cos_inner = math.cos(math.radians(soft / 2))
        lights.append(light)
    return lights


def sky_lights(world):
    """The sun (direction towards it, irradiance per channel) and the domes' radiances."""
    sun = None
    value = number(key(world, "_sunlight", default="0"), 0.0)
    if value > 0:
        mangle = key(world, "_sun_mangle", "_sunlight_mangle")
        travel = direction_from_mangle(vector(mangle, DEFAULT_SUN_MANGLE) if mangle else DEFAULT_SUN_MANGLE)
        sun = (-travel / np.linalg.norm(travel), SUN_IRRADIANCE * value * colour(key(world, "_sunlight_color")))
    upper = number(key(world, "_sunlight2", default="0"), 0.0)
    lower = number(key(world, "_sunlight3", default="0"), 0.0)
    dome_up = DOME_RADIANCE * upper * colour(key(world, "_sunlight2_color")) if upper > 0 else None
    dome_down = DOME_RADIANCE * lower * colour(key(world, "_sunlight3_color")) if lower > 0 else None
    return sun, dome_up, dome_down


class Scene:
    """The faces, which of them occlude and which are judged, and the Mitsuba scene."""

    def __init__(self, bsp):
        import mitsuba as mi

        self.mi = mi
        self.bsp = bsp
        ents = bsp.entities
        self.world = next((e for e in ents if e.get("classname") == "worldspawn"), {})
        nfaces = len(bsp.faces)
        self.face_model = np.full(nfaces, -1, dtype=np.int64)
        self.face_offset = np.zeros((nfaces, 3))
        visible_model = np.zeros(len(bsp.models), dtype=bool)
        model_offset = np.zeros((len(bsp.models), 3))
        if len(bsp.models):
            visible_model[0] = True
        for e in ents:
            m = e.get("model", "")
            if m.startswith("*"):
                try:
                    idx = int(m[1:])
                except ValueError:
                    continue
                cls = e.get("classname", "")
                if 0 < idx < len(bsp.models):
                    visible_model[idx] = not cls.startswith("trigger_") and not cls.startswith(MOVING_MODEL_CLASSES)
                    model_offset[idx] = vector(e.get("origin", "0 0 0"))
        for idx, model in enumerate(bsp.models):
            first, count = int(model["firstface"]), int(model["numfaces"])
            if first < 0 or count < 0 or first + count > nfaces:
                raise BspError(f"{bsp.path}: model {idx}'s faces lie outside the face lump")
            if visible_model[idx]:
                self.face_model[first : first + count] = idx
                self.face_offset[first : first + count] = model_offset[idx]
        names = [bsp.texture_name(f) for f in range(nfaces)]
        self.is_sky = np.array([n.startswith("sky") for n in names])
        self.is_liquid = np.array([n.startswith("*") for n in names])
        # Fences: a `{` texture's holes let light through, as engines draw them.
        self.is_fence = np.array([n.startswith("{") and bsp.tex_pixels[bsp.tex_miptex[bsp.faces[f]["texinfo"]]]
                                  is not None for f, n in enumerate(names)], dtype=bool)
        flags = bsp.tex_flags[bsp.faces["texinfo"]]
        in_scene = self.face_model >= 0
        self.occludes = in_scene & ~self.is_liquid
        self.lightmapped = in_scene & ~self.is_sky & ~self.is_liquid & ((flags & TEX_SPECIAL) == 0)
        self.names = names
        self._build_mesh()

    def _build_mesh(self):
        mi, bsp = self.mi, self.bsp
        verts, tris, tri_face = [], [], []
        base = 0
        for f in np.nonzero(self.occludes)[0]:
            v = bsp.face_vertices(f) + self.face_offset[f]
            k = len(v)
            if k < 3:
                continue
            verts.append(v)
            fan = np.stack([np.zeros(k - 2, dtype=np.int64), np.arange(1, k - 1), np.arange(2, k)], axis=1) + base
            tris.append(fan)
            tri_face.append(np.full(k - 2, f))
            base += k
        verts = np.concatenate(verts).astype(np.float32)
        tris = np.concatenate(tris).astype(np.uint32)
        self.tri_face = np.concatenate(tri_face)
        mesh = mi.Mesh("bsp", vertex_count=len(verts), face_count=len(tris), has_vertex_normals=False,
                       has_vertex_texcoords=False)
        params = mi.traverse(mesh)
        params["vertex_positions"] = mi.Float(verts.ravel())
        params["faces"] = mi.UInt32(tris.ravel())
        params.update()
        self.scene = mi.load_dict({"type": "scene", "bsp": mesh})
        self.triangles = len(tris)

    def _rays(self, o, d, maxt):
        mi = self.mi
        ray = mi.Ray3f(mi.Point3f(o[:, 0], o[:, 1], o[:, 2]), mi.Vector3f(d[:, 0], d[:, 1], d[:, 2]))
        ray.maxt = mi.Float(maxt)
        return ray

    def occluded(self, o, d, maxt):
        if not self.is_fence.any():
            out = np.empty(len(o), dtype=bool)
            for a in range(0, len(o), RAY_CHUNK):
                b = min(a + RAY_CHUNK, len(o))
                hit = self.scene.ray_test(self._rays(o[a:b].astype(np.float32), d[a:b].astype(np.float32),
                                                     maxt[a:b].astype(np.float32)))
                out[a:b] = np.array(hit, dtype=bool)
            return out
        face, _ = self.first_hit(o, d, maxt)
        return face >= 0

    def _first_hit_once(self, o, d, maxt):
        face = np.full(len(o), -1, dtype=np.int64)
        dist = np.full(len(o), np.inf)
        for a in range(0, len(o), RAY_CHUNK):
            b = min(a + RAY_CHUNK, len(o))
            si = self.scene.ray_intersect(self._rays(o[a:b].astype(np.float32), d[a:b].astype(np.float32),
                                                     maxt[a:b].astype(np.float32)))
            valid = np.array(si.is_valid(), dtype=bool)
            prim = np.array(si.prim_index, dtype=np.int64)
            t = np.array(si.t, dtype=np.float64)
            face[a:b][valid] = self.tri_face[prim[valid]]
            dist[a:b][valid] = t[valid]
        return face, dist

    def first_hit(self, o, d, maxt):
        """Face index and distance of the first surface each ray hits (face -1 when none); a
        fence's hole is no surface: the ray goes on through it."""
        face, dist = self._first_hit_once(o, d, maxt)
        if not self.is_fence.any():
            return face, dist
        travelled = np.zeros(len(o))
        for _ in range(FENCE_LAYERS):
            hit = np.nonzero(face >= 0)[0]
            through = hit[self.is_fence[face[hit]]]
            if len(through):
                points = o[through] + d[through] * (travelled[through] + dist[through])[:, None]
                through = through[self.fence_hole(face[through], points)]
            if not len(through):
                break
            travelled[through] += dist[through] + FENCE_STEP
            left = maxt[through] - travelled[through]
            f2, d2 = self._first_hit_once(o[through] + d[through] * travelled[through, None], d[through],
                                          np.maximum(left, 0.0))
            f2[left <= 0] = -1
            face[through] = f2
            dist[through] = d2
        hit = face >= 0
        dist[hit] += travelled[hit]
        return face, dist

    def fence_hole(self, faces, points):
        """Whether each point (world space) on each fence face lies on a hole of its texture."""
        bsp = self.bsp
        local = points - self.face_offset[faces]
        ti = bsp.faces[faces]["texinfo"]
        vecs = bsp.tex_vecs[ti]
        s = np.einsum("ij,ij->i", vecs[:, 0, :3], local) + vecs[:, 0, 3]
        t = np.einsum("ij,ij->i", vecs[:, 1, :3], local) + vecs[:, 1, 3]
        out = np.zeros(len(faces), dtype=bool)
        miptex = bsp.tex_miptex[ti]
        for m in np.unique(miptex):
            sel = miptex == m
            w, h = bsp.tex_sizes[m]
            x = np.floor(s[sel]).astype(np.int64) % w
            y = np.floor(t[sel]).astype(np.int64) % h
            out[sel] = bsp.tex_pixels[m][y * w + x] == FENCE_TRANSPARENT
        return out


# ================================================================================================
# Luxels and their footprints
# ================================================================================================
def clip_polygon(poly, axis, value, keep_greater):
    out = []
    k = len(poly)
    for i in range(k):
        a, b = poly[i], poly[(i + 1) % k]
        ina = (a[axis] >= value) if keep_greater else (a[axis] <= value)
        inb = (b[axis] >= value) if keep_greater else (b[axis] <= value)
        if ina:
            out.append(a)
        if ina != inb:
            t = (value - a[axis]) / (b[axis] - a[axis])
            out.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
    return out


def polygon_area(poly):
    if len(poly) < 3:
        return 0.0
    s = 0.0
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        s += a[0] * b[1] - b[0] * a[1]
    return abs(s) * 0.5


class FaceLuxels:
    """One face's lightmap layout and its drawn luxels."""

    def __init__(self, bsp, face, offset):
        f = bsp.faces[face]
        self.face = face
        verts = bsp.face_vertices(face)
        vecs = bsp.tex_vecs[f["texinfo"]]
        st = verts @ vecs[:, :3].T + vecs[:, 3]
        # the lightmap's extents as engines and both tools compute them: in single precision
        v32, t32 = verts.astype(np.float32), vecs.astype(np.float32)
        st32 = np.stack([v32[:, 0] * t32[j, 0] + v32[:, 1] * t32[j, 1] + v32[:, 2] * t32[j, 2] + t32[j, 3]
                         for j in range(2)], axis=1)
        mins = np.floor(st32.min(axis=0).astype(np.float64) / LUXEL)
        maxs = np.ceil(st32.max(axis=0).astype(np.float64) / LUXEL)
        # an extreme a hair off a luxel boundary may fall either side of it in a tool's or an
        # engine's arithmetic: such a face's lightmap layout is not certain
        extremes = np.concatenate([st.min(axis=0), st.max(axis=0)]) / LUXEL
        off = np.abs(extremes - np.rint(extremes)) * LUXEL
        self.layout_uncertain = bool(np.any((off > 0) & (off < EXTENT_TOLERANCE)))
        self.mins = mins
        self.width, self.height = int(maxs[0] - mins[0]) + 1, int(maxs[1] - mins[1]) + 1
        normal = bsp.plane_normal[f["plane"]]
        dist = bsp.plane_dist[f["plane"]]
        if f["side"]:
            normal, dist = -normal, -dist
        self.normal = normal
        # texture space (s, t) on the face's plane -> world
        m = np.stack([vecs[0, :3], vecs[1, :3], normal])
        self.st_to_world = np.linalg.inv(m)
        self.plane_rhs = (vecs[0, 3], vecs[1, 3], dist)
        self.offset = offset
        cross = np.cross(vecs[0, :3], vecs[1, :3])
        denom = abs(np.dot(cross, normal))
        self.world_per_tex_area = 1.0 / denom if denom > 0 else 0.0
        self.poly = [tuple(p) for p in st]
        p = np.array(self.poly)
        e = np.roll(p, -1, axis=0) - p
        self.edge_n = np.stack([e[:, 1], -e[:, 0]], axis=1)
        self.edge_c = np.einsum("ij,ij->i", self.edge_n, p)
        # the edge normals point inwards whichever way the polygon winds
        if np.mean(self.edge_n @ p.mean(axis=0) - self.edge_c) < 0:
            self.edge_n, self.edge_c = -self.edge_n, -self.edge_c

    def inside(self, pts):
        return np.all(pts @ self.edge_n.T - self.edge_c >= -1e-9, axis=1)

    def drawn(self):
        """(luxel index, footprint area in texture units^2, whole) for luxels that touch the face."""
        out = []
        ii, jj = np.meshgrid(np.arange(self.width), np.arange(self.height))
        cs = (self.mins[0] + ii.ravel()) * LUXEL
        ct = (self.mins[1] + jj.ravel()) * LUXEL
        half = LUXEL / 2
        corners = np.stack([np.stack([cs + dx, ct + dy], axis=1) for dx in (-half, half) for dy in (-half, half)])
        whole = np.all([self.inside(c) for c in corners], axis=0)
        for k in range(len(cs)):
            if whole[k]:
                out.append((k, LUXEL * LUXEL, True))
                continue
            poly = self.poly
            poly = clip_polygon(poly, 0, cs[k] - half, True)
            if poly:
                poly = clip_polygon(poly, 0, cs[k] + half, False)
            if poly:
                poly = clip_polygon(poly, 1, ct[k] - half, True)
            if poly:
                poly = clip_polygon(poly, 1, ct[k] + half, False)
            area = polygon_area(poly)
            if area > MIN_FOOTPRINT:
                c = np.mean(np.array(poly), axis=0)
                out.append((k, area, False, c))
        return out

    def to_world(self, st):
        rhs = np.stack([st[:, 0] - self.plane_rhs[0], st[:, 1] - self.plane_rhs[1],
                        np.full(len(st), self.plane_rhs[2])], axis=1)
        return rhs @ self.st_to_world.T + self.offset


class DrawnLuxels:
    """Every drawn luxel of the judged faces: its face, place in the lightmap and footprint."""

    def __init__(self, bsp, scene, faces):
        self.layouts = {}
        face, index, area, style_ofs, whole, centroid = [], [], [], [], [], []
        for f in faces:
            fl = FaceLuxels(bsp, f, scene.face_offset[f])
            self.layouts[f] = fl
            rec = bsp.faces[f]
            styles = list(rec["styles"])
            ofs = -1
            if rec["lightofs"] >= 0 and 0 in styles:
                ofs = int(rec["lightofs"]) + styles.index(0) * fl.width * fl.height
            for item in fl.drawn():
                face.append(f)
                index.append(item[0])
                area.append(item[1] * fl.world_per_tex_area)
                style_ofs.append(ofs)
                whole.append(item[2])
                centroid.append(item[3] if len(item) > 3 else (np.nan, np.nan))
        self.face = np.array(face, dtype=np.int64)
        self.index = np.array(index, dtype=np.int64)
        self.area = np.array(area)
        self.style_ofs = np.array(style_ofs, dtype=np.int64)
        self.whole = np.array(whole, dtype=bool)
        self.centroid = np.array(centroid).reshape(-1, 2)

    def __len__(self):
        return len(self.face)

    def samples(self, which, grid, edge_grid, rng):
        """Jittered sample points of the luxels `which`, BATCHES independent sets of each.

        Returns point, normal, position in `which`, batch and weight arrays; each (luxel, batch)'s
        weights sum to 1."""
        pts, nrm, lux, bat, wts = [], [], [], [], []
        which = np.asarray(which)
        for f in np.unique(self.face[which]):
            fl = self.layouts[f]
            mine = np.nonzero(self.face[which] == f)[0]
            for is_whole in (True, False):
                sel = mine[self.whole[which[mine]] == is_whole]
                if not len(sel):
                    continue
                g = grid if is_whole else edge_grid
                cell = LUXEL / g
                base = np.arange(g) * cell - LUXEL / 2
                gs, gt = np.meshgrid(base, base)
                offs = np.stack([gs.ravel(), gt.ravel()], axis=1)
                k = self.index[which[sel]]
                centre = np.stack([(fl.mins[0] + k % fl.width) * LUXEL, (fl.mins[1] + k // fl.width) * LUXEL], axis=1)
                st = centre[:, None, None, :] + offs[None, None] + rng.random((len(sel), BATCHES, g * g, 2)) * cell
                ids = np.broadcast_to(sel[:, None, None], st.shape[:3])
                bts = np.broadcast_to(np.arange(BATCHES)[None, :, None], st.shape[:3])
                if is_whole:
                    keep = np.ones(st.shape[:3], dtype=bool)
                else:
                    keep = fl.inside(st.reshape(-1, 2)).reshape(st.shape[:3])
                    # a batch with no candidate on the face takes the footprint's centroid
                    empty = ~keep.any(axis=2)
                    if empty.any():
                        li, bi = np.nonzero(empty)
                        st[li, bi, 0] = self.centroid[which[sel[li]]]
                        keep[li, bi, 0] = True
                count = keep.sum(axis=2, keepdims=True)
                w = np.broadcast_to(1.0 / count, keep.shape)
                pts.append(fl.to_world(st[keep]))
                nrm.append(np.repeat(fl.normal[None], keep.sum(), axis=0))
                lux.append(ids[keep])
                bat.append(bts[keep])
                wts.append(w[keep])
        return (np.concatenate(pts), np.concatenate(nrm), np.concatenate(lux), np.concatenate(bat),
                np.concatenate(wts))


# ================================================================================================
# Irradiance
# ================================================================================================
def cosine_directions(normal, rng, count):
    """`count` cosine-weighted directions about each normal, stratified in count's square grid."""
    n = len(normal)
    g = int(math.isqrt(count))
    u = (np.arange(count) % g + rng.random((n, count))) / g
    v = (np.arange(count) // g + rng.random((n, count))) / g
    r, phi = np.sqrt(u), 2 * math.pi * v
    x, y, z = r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0.0, 1 - u))
    a = np.where(np.abs(normal[:, :1]) > 0.9, np.array([[0.0, 1.0, 0.0]]), np.array([[1.0, 0.0, 0.0]]))
    t = np.cross(normal, a)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(normal, t)
    return (x[..., None] * t[:, None] + y[..., None] * b[:, None] + z[..., None] * normal[:, None])


def direct_irradiance(scene, lights, sun, dome_up, dome_down, pts, nrm, rng, log):
    """Per-sample irradiance (levels, RGB) from lights, sun and sky domes."""
    n = len(pts)
    e = np.zeros((n, 3))
    origin = pts + nrm * RAY_OFFSET
    pending = {"o": [], "d": [], "t": [], "i": [], "c": [], "count": 0}
    rays = 0

    def flush():
        nonlocal rays
        if not pending["count"]:
            return
        o = np.concatenate(pending["o"])
        d = np.concatenate(pending["d"])
        t = np.concatenate(pending["t"])
        i = np.concatenate(pending["i"])
        c = np.concatenate(pending["c"])
        lit = ~scene.occluded(o, d, t)
        rays += len(o)
        for ch in range(3):
            e[:, ch] += np.bincount(i[lit], weights=c[lit, ch], minlength=n)
        for k in pending:
            pending[k] = [] if k != "count" else 0

    for light in lights:
        to = light.origin - origin
        dist = np.linalg.norm(to, axis=1)
        ok = dist > RAY_OFFSET
        d = to / np.maximum(dist, 1e-9)[:, None]
        cos = np.einsum("ij,ij->i", d, nrm)
        scale = cos / np.maximum(dist, 1e-9) ** 2
        if light.spot_dir is not None:
            c_spot = -(d @ light.spot_dir)
            if light.cos_inner > light.cos_outer:
                spot = np.clip((c_spot - light.cos_outer) / (light.cos_inner - light.cos_outer), 0.0, 1.0)
            else:
                spot = (c_spot >= light.cos_outer).astype(np.float64)
            scale = scale * spot
        ok &= scale > 0
        level = scale * light.intensity.max()
        p = np.minimum(1.0, level / ROULETTE_LEVEL)
        ok &= rng.random(n) < p
        idx = np.nonzero(ok)[0]
        if not len(idx):
            continue
        contrib = (scale[idx] / p[idx])[:, None] * light.intensity[None]
        pending["o"].append(origin[idx])
        pending["d"].append(d[idx])
        pending["t"].append(dist[idx] - RAY_OFFSET)
        pending["i"].append(idx)
        pending["c"].append(contrib)
        pending["count"] += len(idx)
        if pending["count"] >= 4 * RAY_CHUNK:
            flush()
    flush()
    log(f"point and spot lights: {len(lights)}, {rays} shadow rays")

    if sun is not None:
        to_sun, irr = sun
        cos = nrm @ to_sun
        idx = np.nonzero(cos > 0)[0]
        face, _ = scene.first_hit(origin[idx], np.repeat(to_sun[None], len(idx), axis=0),
                                  np.full(len(idx), SKY_DISTANCE))
        lit = (face >= 0) & scene.is_sky[np.maximum(face, 0)]
        e[idx[lit]] += cos[idx[lit], None] * irr[None]
        log(f"sun: {len(idx)} rays, {lit.mean() if len(lit) else 0:.3f} reach the sky")

    if dome_up is not None or dome_down is not None:
        total = 0
        for a in range(0, n, RAY_CHUNK // SKY_RAYS):
            b = min(n, a + RAY_CHUNK // SKY_RAYS)
            dirs = cosine_directions(nrm[a:b], rng, SKY_RAYS)
            o = np.repeat(origin[a:b], SKY_RAYS, axis=0)
            dd = dirs.reshape(-1, 3)
            face, _ = scene.first_hit(o, dd, np.full(len(o), SKY_DISTANCE))
            sky = (face >= 0) & scene.is_sky[np.maximum(face, 0)]
            rad = np.zeros((len(o), 3))
            if dome_up is not None:
                rad[sky & (dd[:, 2] > 0)] = dome_up
            if dome_down is not None:
                rad[sky & (dd[:, 2] < 0)] = dome_down
            # cosine-weighted: E = pi * mean radiance
            e[a:b] += math.pi * rad.reshape(b - a, SKY_RAYS, 3).mean(axis=1)
            total += len(o)
        log(f"sky domes: {total} rays")
    return e


# ================================================================================================
# Interreflection
# ================================================================================================
class RadiosityCache:
    """Radiant exitance per luxel of every lightmapped face, looked up where gather rays land."""

    def __init__(self, bsp, scene, albedo, rng, lights, sun, dome_up, dome_down, log):
        faces = np.nonzero(scene.lightmapped)[0]
        self.layout, self.start = {}, {}
        centres, normals, owner = [], [], []
        pos = 0
        for f in faces:
            fl = FaceLuxels(bsp, f, scene.face_offset[f])
            ii, jj = np.meshgrid(np.arange(fl.width), np.arange(fl.height))
            st = np.stack([(fl.mins[0] + ii.ravel()) * LUXEL, (fl.mins[1] + jj.ravel()) * LUXEL], axis=1)
            # a luxel's point is kept on the face so that it sees what the face sees
            inside = fl.inside(st)
            if not inside.all():
                c = np.array(fl.poly).mean(axis=0)
                st[~inside] = c + (st[~inside] - c) * 0.98
                still = ~fl.inside(st)
                st[still] = c
            self.layout[f] = fl
            self.start[f] = pos
            pos += len(st)
            centres.append(fl.to_world(st))
            normals.append(np.repeat(fl.normal[None], len(st), axis=0))
            owner.append(np.full(len(st), f))
        self.points = np.concatenate(centres)
        self.normals = np.concatenate(normals)
        self.albedo = np.concatenate([np.repeat(albedo[f][None], len(o), axis=0) for f, o in zip(faces, owner)])
        self.direct = direct_irradiance(scene, lights, sun, dome_up, dome_down, self.points, self.normals, rng, log)
        self.faces = faces

    def lookup(self, face, hit_points):
        """Index of the cache luxel nearest each hit point on its face (-1 for faces without one)."""
        out = np.full(len(face), -1, dtype=np.int64)
        for f in np.unique(face):
            if f < 0 or f not in self.start:
                continue
            sel = np.nonzero(face == f)[0]
            fl = self.layout[f]
            local = hit_points[sel] - fl.offset
            vecs = fl.st_to_world  # world = M^-1 rhs; rhs = (s - s0, t - t0, d)
            m = np.linalg.inv(vecs)
            st = local @ m[:2].T + np.array(fl.plane_rhs[:2])
            i = np.clip(np.rint(st[:, 0] / LUXEL - fl.mins[0]), 0, fl.width - 1).astype(np.int64)
            j = np.clip(np.rint(st[:, 1] / LUXEL - fl.mins[1]), 0, fl.height - 1).astype(np.int64)
            out[sel] = self.start[f] + j * fl.width + i
        return out


def gather(scene, cache, exitance, pts, nrm, rng):
    """Irradiance at each point from the diffuse surfaces it sees, whose radiance is exitance/pi."""
    n = len(pts)
    e = np.zeros((n, 3))
    origin = pts + nrm * RAY_OFFSET
    step = max(1, RAY_CHUNK // BOUNCE_RAYS)
    for a in range(0, n, step):
        b = min(n, a + step)
        dirs = cosine_directions(nrm[a:b], rng, BOUNCE_RAYS).reshape(-1, 3)
        o = np.repeat(origin[a:b], BOUNCE_RAYS, axis=0)
        face, t = scene.first_hit(o, dirs, np.full(len(o), SKY_DISTANCE))
        hit = face >= 0
        idx = np.full(len(o), -1, dtype=np.int64)
        hp = o[hit] + dirs[hit] * t[hit, None]
        idx[hit] = cache.lookup(face[hit], hp)
        rad = np.zeros((len(o), 3))
        good = idx >= 0
        # the surface hit from its back faces away: it sends nothing this way
        facing = np.einsum("ij,ij->i", cache.normals[np.maximum(idx, 0)], dirs) < 0
        good &= facing
        rad[good] = exitance[idx[good]] / math.pi
        e[a:b] = math.pi * rad.reshape(b - a, BOUNCE_RAYS, 3).mean(axis=1)
    return e


def bounce_exitance(scene, cache, rng, bounces, log):
    """Each cache luxel's radiant exitance once light has bounced `bounces` times (0: until no
    luxel changes by more than BOUNCE_CONVERGED)."""
    limit = bounces if bounces > 0 else BOUNCE_ITERATION_LIMIT
    indirect = np.zeros_like(cache.direct)
    for it in range(limit - 1):
        new_indirect = gather(scene, cache, cache.albedo * (cache.direct + indirect), cache.points,
                              cache.normals, rng)
        change = np.abs(new_indirect - indirect).max()
        indirect = new_indirect
        log(f"bounce {it + 1}: largest change {change:.3f} levels")
        if bounces == 0 and change < BOUNCE_CONVERGED:
            break
    return cache.albedo * (cache.direct + indirect)


# ================================================================================================
# Comparison
# ================================================================================================
def lightmap_values(bsp, face, index, style_ofs):
    """Each luxel's style-0 light per channel, as the lightmap holds it (0 where it has none)."""
    out = np.zeros((len(face), 3))
    has = style_ofs >= 0
    at = style_ofs[has] + index[has]
    if bsp.lit is not None:
        out[has] = bsp.lit[at]
    else:
        out[has] = bsp.lighting[at][:, None]
    return out


def lightmap_size_mismatches(bsp, faces_layout):
    """Faces whose lightmap size we compute would overrun the next face's lightmap."""
    ofs = bsp.faces["lightofs"].astype(np.int64)
    order = np.argsort(ofs, kind="stable")
    nxt = {}
    valid = [f for f in order if ofs[f] >= 0]
    for a, b in zip(valid, valid[1:]):
        if ofs[b] > ofs[a]:
            nxt[a] = ofs[b]
    if valid:
        nxt.setdefault(valid[-1], len(bsp.lighting))
    bad = set()
    for f, (size, nstyles) in faces_layout.items():
        if ofs[f] >= 0 and f in nxt and ofs[f] + size * nstyles > nxt[f]:
            bad.add(f)
        elif ofs[f] >= 0 and ofs[f] + size * nstyles > len(bsp.lighting):
            bad.add(f)
    return bad


def saturate(rgb):
    """Scale a colour down so that no channel exceeds what a lightmap byte holds."""
    m = rgb.max(axis=-1, keepdims=True)
    return np.where(m > LIGHTMAP_MAX, rgb * (LIGHTMAP_MAX / np.maximum(m, 1e-9)), rgb)


def error_breakdown(weights, diff, reference, whole):
    """The error split by kind of luxel: where on the face, how much light."""
    classes = [
        ("whole luxels (footprint inside the face)", whole),
        ("edge luxels (footprint cut by the face's edge)", ~whole),
        ("dark (reference under 1 level)", reference.max(axis=1) < 1.0),
        ("dim (reference 1 to 32 levels)", (reference.max(axis=1) >= 1.0) & (reference.max(axis=1) < 32.0)),
        ("saturated (reference at 255)", reference.max(axis=1) >= LIGHTMAP_MAX - 0.5),
    ]
    sq = (weights[:, None] * diff**2).sum(axis=1)
    total_sq, total_w = sq.sum(), weights.sum()
    rows = []
    for name, m in classes:
        w = weights[m].sum()
        rows.append({
            "class": name,
            "area_share": float(w / total_w) if total_w else 0.0,
            "error_share": float(sq[m].sum() / total_sq) if total_sq else 0.0,
            "rmse": math.sqrt(float(sq[m].sum() / (w * diff.shape[1]))) if w else 0.0,
            "bias": float((weights[m, None] * diff[m]).sum() / (w * diff.shape[1])) if w else 0.0,
        })
    return rows


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bsp")
    ap.add_argument("--every", type=int, default=0, help="judge every Nth lightmapped face (default: automatic)")
    ap.add_argument("--max-luxels", type=int, default=DEFAULT_MAX_LUXELS,
                    help="the automatic subset judges about this many luxels at most")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--bounce", type=int, nargs="?", const=0, default=None,
                    help="add diffuse interreflection: N bounces, or until converged when N is left out")
    ap.add_argument("--palette", help="palette.lmp for the textures' mean colours")
    ap.add_argument("--json", help="write the figures to this JSON file")
    ap.add_argument("--faces-csv", help="write each judged face's error to this CSV file")
    ap.add_argument("--luxels-npz", help="write every judged luxel's reference, lightmap value, noise and weight")
    ap.add_argument("--no-cache", action="store_true", help="neither read nor write the cached reference")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv[1:])
    log = (lambda *_: None) if args.quiet else (lambda s: print(s, file=sys.stderr, flush=True))
    t0 = time.time()
    try:
        import mitsuba as mi
    except ImportError:
        print("error: Mitsuba 3 is not installed (pip install mitsuba numpy)", file=sys.stderr)
        return 3
    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception as e:  # noqa: BLE001 - Mitsuba raises plain exceptions for a missing variant
        print(f"error: Mitsuba's llvm_ad_rgb variant is unavailable ({e}); it needs libLLVM", file=sys.stderr)
        return 3
    try:
        bsp = Bsp(args.bsp)
    except (OSError, BspError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    scene = Scene(bsp)
    lights = style0_lights(bsp.entities)
    sun, dome_up, dome_down = sky_lights(scene.world)
    candidates = np.nonzero(scene.lightmapped)[0]
    # faces whose texture is fullbright in every texel show no light: not judged
    palette, palette_path = load_palette(args.bsp, args.palette)
    albedo = np.full((len(bsp.faces), 3), 0.5)
    judged = []
    for f in candidates:
        m = bsp.tex_miptex[bsp.faces[f]["texinfo"]]
        pix = bsp.tex_pixels[m] if 0 <= m < len(bsp.tex_pixels) else None
        if pix is not None:
            if np.all(pix >= FULLBRIGHT_FIRST):
                continue
            if palette is not None:
                albedo[f] = palette[pix].mean(axis=0)
        judged.append(f)
    judged = np.array(judged, dtype=np.int64)
    if not len(judged):
        print("error: the BSP has no lightmapped face to judge", file=sys.stderr)
        return 1
    # faces whose lightmap layout is uncertain are not judged
    judged = np.array([f for f in judged if not FaceLuxels(bsp, f, scene.face_offset[f]).layout_uncertain],
                      dtype=np.int64)
    # a fixed subset: every Nth judged face in face order
    every = args.every
    if every <= 0:
        luxels = 0
        for f in judged:
            fl = FaceLuxels(bsp, f, scene.face_offset[f])
            luxels += fl.width * fl.height
        every = max(1, math.ceil(luxels / max(1, args.max_luxels)))
    subset = judged[::every]
    layout = {}
    for f in subset:
        fl = FaceLuxels(bsp, f, scene.face_offset[f])
        nst = sum(1 for s in bsp.faces[f]["styles"] if s != 255)
        layout[f] = (fl.width * fl.height, nst)
    bad = lightmap_size_mismatches(bsp, layout)
    subset = np.array([f for f in subset if f not in bad], dtype=np.int64)
    log(f"{bsp.path}: {bsp.kind}, {len(bsp.faces)} faces, {scene.triangles} occluding triangles, "
        f"{len(lights)} style-0 lights, sun {'yes' if sun else 'no'}, "
        f"domes {'yes' if dome_up is not None or dome_down is not None else 'no'}, "
        f"colour from {'.lit' if bsp.lit is not None else 'the grey lightmap'}")
    log(f"subset: 1 in {every} of {len(judged)} lightmapped faces -> {len(subset)} faces"
        + (f" ({len(bad)} left out: lightmap size disagrees)" if bad else ""))

    light_digest = json.dumps([[l.origin.tolist(), l.intensity.tolist(), None if l.spot_dir is None else
                                [l.spot_dir.tolist(), l.cos_outer, l.cos_inner]] for l in lights]
                              + [None if sun is None else [sun[0].tolist(), sun[1].tolist()],
                                 None if dome_up is None else dome_up.tolist(),
                                 None if dome_down is None else dome_down.tolist(),
                                 np.nonzero(scene.occludes)[0].tolist(), subset.tolist()])
    digest = hashlib.sha256((bsp.geometry_digest() + light_digest + json.dumps(
        [CACHE_VERSION, every, args.seed, args.bounce, BATCHES, GRID, EDGE_GRID, FINE_GRID, FINE_NOISE, SKY_RAYS,
         BOUNCE_RAYS, ROULETTE_LEVEL, palette_path is not None])).encode()).hexdigest()[:32]
    cache_dir = os.path.join(os.environ.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "slipgate-reference")
    cache_path = os.path.join(cache_dir, digest + ".npz")
    drawn = DrawnLuxels(bsp, scene, subset)
    if not args.no_cache and os.path.exists(cache_path):
        cached = np.load(cache_path)
        luxel_batches = cached["luxel_batches"]
        ref_seconds = float(cached["seconds"])
        log(f"reference read from the cache {cache_path}")
    else:
        rng = np.random.default_rng(args.seed)
        cache = None
        if args.bounce is not None:
            cache = RadiosityCache(bsp, scene, albedo, rng, lights, sun, dome_up, dome_down, log)
            bounced = bounce_exitance(scene, cache, rng, args.bounce, log)

        def estimate(which, grid, edge_grid):
            pts, nrm, lux, bat, wts = drawn.samples(which, grid, edge_grid, rng)
            log(f"{len(which)} luxels, {len(pts)} sample points")
            e = direct_irradiance(scene, lights, sun, dome_up, dome_down, pts, nrm, rng, log)
            if cache is not None:
                e += gather(scene, cache, bounced, pts, nrm, rng)
            # what a lightmap can hold at each point: the display saturates point by point
            e = saturate(e)
            out = np.zeros((len(which), BATCHES, 3))
            key_index = lux * BATCHES + bat
            for ch in range(3):
                out[..., ch] = np.bincount(key_index, weights=wts * e[:, ch],
                                           minlength=len(which) * BATCHES).reshape(len(which), BATCHES)
            return out

        everyone = np.arange(len(drawn))
        luxel_batches = estimate(everyone, GRID, EDGE_GRID)
        # luxels whose batches disagree (shadow edges, steep falloff) are estimated again, afresh
        # and with many more samples: the new estimate does not depend on the first
        spread = np.sqrt(saturate(luxel_batches).var(axis=1, ddof=1).max(axis=1) / BATCHES)
        noisy = np.nonzero(spread > FINE_NOISE)[0]
        if len(noisy):
            luxel_batches[noisy] = estimate(noisy, FINE_GRID, FINE_GRID)
        ref_seconds = time.time() - t0
        if not args.no_cache:
            os.makedirs(cache_dir, exist_ok=True)
            tmp = cache_path + f".{os.getpid()}.tmp.npz"
            np.savez_compressed(tmp, luxel_batches=luxel_batches, seconds=ref_seconds)
            os.replace(tmp, cache_path)
    weights = drawn.area
    reference = saturate(luxel_batches.mean(axis=1))
    # the noise: each luxel's standard error from the spread of its batches
    batch_sat = saturate(luxel_batches)
    var = batch_sat.var(axis=1, ddof=1) / BATCHES
    lm = lightmap_values(bsp, drawn.face, drawn.index, drawn.style_ofs)
    if bsp.lit is None:
        reference_cmp = reference.max(axis=1, keepdims=True)
        lm_cmp = lm[:, :1]
        var_cmp = var.max(axis=1, keepdims=True)
    else:
        reference_cmp, lm_cmp, var_cmp = reference, lm, var
    diff = lm_cmp - reference_cmp
    wsum = weights.sum()
    rmse = math.sqrt(float((weights[:, None] * diff**2).sum() / (wsum * diff.shape[1])))
    noise = math.sqrt(float((weights[:, None] * var_cmp).sum() / (wsum * diff.shape[1])))
    bias = float((weights[:, None] * diff).sum() / (wsum * diff.shape[1]))
    mean_ref = float((weights[:, None] * reference_cmp).sum() / (wsum * diff.shape[1]))
    breakdown = error_breakdown(weights, diff, reference_cmp, drawn.whole)
    for row in breakdown:
        log(f"  {row['class']:<44} {row['area_share'] * 100:5.1f}% of the area, "
            f"{row['error_share'] * 100:5.1f}% of the squared error, rmse {row['rmse']:6.2f}, "
            f"mean lightmap - reference {row['bias']:+6.2f}")
    seconds = time.time() - t0
    log(f"mean reference {mean_ref:.2f} levels, mean lightmap - reference {bias:+.3f} levels, "
        f"{(reference_cmp >= LIGHTMAP_MAX - 0.5).mean() * 100:.1f}% of values saturated; "
        f"reference computed in {ref_seconds:.1f} s, this run {seconds:.1f} s")
    if args.faces_csv:
        face_of = drawn.face
        with open(args.faces_csv, "w") as f:
            f.write("face,texture,luxels,area,mean_reference,mean_lightmap,rmse,normal_x,normal_y,normal_z\n")
            for face in np.unique(face_of):
                sel = face_of == face
                w = weights[sel]
                d = diff[sel]
                fl = FaceLuxels(bsp, face, scene.face_offset[face])
                f.write(f"{face},{scene.names[face]},{sel.sum()},{w.sum():.1f},"
                        f"{(w[:, None] * reference_cmp[sel]).sum() / w.sum() / d.shape[1]:.3f},"
                        f"{(w[:, None] * lm_cmp[sel]).sum() / w.sum() / d.shape[1]:.3f},"
                        f"{math.sqrt((w[:, None] * d**2).sum() / w.sum() / d.shape[1]):.3f},"
                        f"{fl.normal[0]:.3f},{fl.normal[1]:.3f},{fl.normal[2]:.3f}\n")
    if args.luxels_npz:
        np.savez_compressed(args.luxels_npz, face=drawn.face, index=drawn.index, whole=drawn.whole,
                            reference=reference_cmp,
                            lightmap=lm_cmp, variance=var_cmp, weight=weights, batches=luxel_batches)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"bsp": args.bsp, "rmse": rmse, "drawn_luxels": len(drawn), "noise": noise,
                       "bias": bias, "mean_reference": mean_ref, "every": every, "faces": int(len(subset)),
                       "bounce": args.bounce, "colour": bsp.lit is not None, "seconds": seconds,
                       "breakdown": breakdown,
                       "reference_seconds": ref_seconds}, f, indent=1)
    print(f"subset: 1 in {every} lightmapped faces ({len(subset)} of {len(judged)} faces); "
          f"reference time {ref_seconds:.1f} s")
    print(f"rmse {rmse:.3f} over {len(drawn)} drawn luxels; noise {noise:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
