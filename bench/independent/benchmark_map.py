#!/usr/bin/env python3
"""Write the benchmark form of a Quake .map: the lighting that both light tools and a physical
model (reference.py) can agree on.

Usage: benchmark_map.py IN.map OUT.map

Needs only the Python standard library. Brushes are copied byte for byte; only entity keys
change:

- Every light entity (classname light*) is a point light with inverse-square falloff
  (`delay 2`), Lambert's cosine law (`_anglescale 1`), its distance scale left at 1 (`wait`
  removed) and an explicit brightness (`light 300` where the key was missing). Spotlights
  (`target`, `mangle`, `angle`, `_softangle`) and `_color` stay: the reference models them.
- Keys that describe no physical light are removed from lights: `_falloff`, `_deviance`,
  `_samples`, `_dirt*`, `_bleed`, `_anglesense`, `_project_*`, `_bounce*`, `_nostaticlight`,
  channel masks. Lights whose light is not positive (antilights), surface-light templates
  (`_surface`) and lights that are suns or sky domes themselves (`_sun`, `_sunlight2`,
  `_sunlight3`) are left out.
- Worldspawn keeps its sun (`_sunlight`, `_sun_mangle`/`_sunlight_mangle`, `_sunlight_color`)
  and sky domes (`_sunlight2`, `_sunlight3` and their colours), gains `_anglescale 1`, and loses
  minlight (`light`, `_minlight*`, `_mincolor`), `_range`, `_dist`, `_gamma`, `_dirt*`, sun
  penumbra and deviance, `_bounce*`, `_phong*`, the lightmap scale keys and the second sun.
- Every brush entity that stays put (not a trigger, door, plat, train, button or rotating
  model) casts shadows (`_shadow 1`, as a real wall does); every brush entity loses minlight,
  phong, dirt, `_alpha`, `_lightignore` and switchable or self-only shadows.
"""
import sys

LIGHT_KEYS_DROPPED_PREFIXES = (
    "_dirt",
    "_project_",
    "_bounce",
    "_surface",
    "_sunlight",
)
LIGHT_KEYS_DROPPED = {
    "wait",
    "_wait",
    "_falloff",
    "_deviance",
    "_samples",
    "_bleed",
    "_anglesense",
    "_anglescale",
    "_nostaticlight",
    "_light_channel_mask",
    "_shadow_channel_mask",
    "_sun",
    "_suntexture",
    "_noisetype",
    "_noisescale",
    "_noise",
    "delay",
    "_formula",
}
WORLD_KEYS_DROPPED_PREFIXES = (
    "_minlight",
    "_dirt",
    "_bounce",
    "_phong",
    "_sun2",
    "_surflight",
)
WORLD_KEYS_DROPPED = {
    "light",
    "_light",
    "_mincolor",
    "_range",
    "_dist",
    "_gamma",
    "_anglescale",
    "_anglesense",
    "_sunlight_penumbra",
    "_sun_deviance",
    "_sunlight_dirt",
    "_sunlight2_dirt",
    "_lightmap_scale",
    "_world_units_per_luxel",
    "_maxlight",
    "_addmin",
    "_spotlightautofalloff",
    "_lightignore",
}
BRUSH_KEYS_DROPPED_PREFIXES = ("_minlight", "_phong", "_dirt", "_shadow", "_surflight")
BRUSH_KEYS_DROPPED = {
    "light",
    "_light",
    "_mincolor",
    "_alpha",
    "_lightignore",
    "_switchableshadow",
    "_lightcolorscale",
    "_object_channel_mask",
    "_bounce",
    "_nodirt",
}
DEFAULT_LIGHT = 300.0
# Brush entities that move: a baked shadow of theirs would be wrong wherever they go, so they
# cast none (as both tools do by default) and the reference leaves them out.
MOVING_CLASSES = ("func_door", "func_plat", "func_train", "func_button", "func_rotat", "rotate_", "func_bob",
                  "func_movewall")


class MapError(Exception):
    pass


def parse_entities(text):
    """Split a .map into entities: each a list of (key, value) pairs and the raw text of its
    brushes. Comments outside quotes are skipped; brush text is kept exactly."""
    entities = []
    i, n = 0, len(text)
    line = 1

    def skip_space(i, line):
        while i < n:
            c = text[i]
            if c == "\n":
                line += 1
                i += 1
            elif c.isspace():
                i += 1
            elif text.startswith("//", i):
                while i < n and text[i] != "\n":
                    i += 1
            else:
                break
        return i, line

    while True:
        i, line = skip_space(i, line)
        if i >= n:
            break
        if text[i] != "{":
            raise MapError(f"line {line}: expected '{{' to open an entity")
        i += 1
        pairs, brushes = [], []
        while True:
            i, line = skip_space(i, line)
            if i >= n:
                raise MapError(f"line {line}: entity {len(entities)} is not closed")
            c = text[i]
            if c == "}":
                i += 1
                break
            if c == '"':
                strings = []
                for _ in range(2):
                    i, line = skip_space(i, line)
                    if i >= n or text[i] != '"':
                        raise MapError(f"line {line}: entity {len(entities)}: a key without a value")
                    end = text.find('"', i + 1)
                    if end < 0:
                        raise MapError(f"line {line}: unterminated string")
                    strings.append(text[i + 1 : end])
                    line += text.count("\n", i, end)
                    i = end + 1
                pairs.append((strings[0], strings[1]))
            elif c == "{":
                # Braces count only as whole tokens: texture names such as {fence start with one.
                start, depth = i, 0
                while i < n:
                    ch = text[i]
                    if ch == "\n":
                        line += 1
                        i += 1
                        continue
                    if ch.isspace():
                        i += 1
                        continue
                    if ch == '"':
                        end = text.find('"', i + 1)
                        if end < 0:
                            raise MapError(f"line {line}: unterminated string")
                        line += text.count("\n", i, end)
                        i = end + 1
                        continue
                    if text.startswith("//", i):
                        while i < n and text[i] != "\n":
                            i += 1
                        continue
                    end = i
                    while end < n and not text[end].isspace():
                        end += 1
                    token = text[i:end]
                    i = end
                    if token == "{":
                        depth += 1
                    elif token == "}":
                        depth -= 1
                        if depth == 0:
                            break
                else:
                    raise MapError(f"line {line}: entity {len(entities)}: brush is not closed")
                brushes.append(text[start:i])
            else:
                raise MapError(f"line {line}: entity {len(entities)}: unexpected {c!r}")
        entities.append((pairs, brushes))
    return entities


def first_number(value, default):
    try:
        return float(value.split()[0])
    except (ValueError, IndexError):
        return default


def dropped(key, exact, prefixes):
    k = key.lower()
    return k in exact or any(k.startswith(p) for p in prefixes)


def benchmark_light(pairs):
    """The benchmark form of a light's keys, or None when the light is left out."""
    keys = {k.lower(): v for k, v in pairs}
    if "_surface" in keys:
        return None
    for sunlike in ("_sun", "_sunlight2", "_sunlight3"):
        if first_number(keys.get(sunlike, "0"), 0.0) != 0.0:
            return None
    light = first_number(keys["light"], DEFAULT_LIGHT) if "light" in keys else DEFAULT_LIGHT
    if light <= 0.0:
        return None
    out = []
    for k, v in pairs:
        if k.lower() == "light":
            continue
        if dropped(k, LIGHT_KEYS_DROPPED, LIGHT_KEYS_DROPPED_PREFIXES):
            continue
        out.append((k, v))
    out += [("light", f"{light:g}"), ("delay", "2"), ("_anglescale", "1")]
    return out


def benchmark_world(pairs):
    out = [
        (k, v)
        for k, v in pairs
        if not dropped(k, WORLD_KEYS_DROPPED, WORLD_KEYS_DROPPED_PREFIXES)
    ]
    return out + [("_anglescale", "1")]


def benchmark_brush_entity(classname, pairs):
    out = [
        (k, v)
        for k, v in pairs
        if not dropped(k, BRUSH_KEYS_DROPPED, BRUSH_KEYS_DROPPED_PREFIXES)
    ]
    if not classname.startswith("trigger_") and not classname.startswith(MOVING_CLASSES):
        out.append(("_shadow", "1"))
    return out


def benchmark_form(entities):
    result = []
    for pairs, brushes in entities:
        classname = next((v for k, v in pairs if k.lower() == "classname"), "")
        if classname == "worldspawn":
            pairs = benchmark_world(pairs)
        elif classname.startswith("light"):
            pairs = benchmark_light(pairs)
            if pairs is None:
                continue
        elif brushes and classname not in ("func_group", "func_detail"):
            pairs = benchmark_brush_entity(classname, pairs)
        result.append((pairs, brushes))
    return result


def write_map(entities):
    out = []
    for pairs, brushes in entities:
        out.append("{\n")
        for k, v in pairs:
            out.append(f'"{k}" "{v}"\n')
        for brush in brushes:
            out.append(brush + "\n")
        out.append("}\n")
    return "".join(out)


def main(argv):
    if len(argv) != 3:
        print("usage: benchmark_map.py IN.map OUT.map", file=sys.stderr)
        return 2
    src, dst = argv[1], argv[2]
    try:
        with open(src, encoding="latin-1") as f:
            entities = parse_entities(f.read())
    except OSError as e:
        print(f"error: {src}: {e.strerror}", file=sys.stderr)
        return 1
    except MapError as e:
        print(f"error: {src}: {e}", file=sys.stderr)
        return 1
    text = write_map(benchmark_form(entities))
    tmp = dst + ".tmp"
    try:
        with open(tmp, "w", encoding="latin-1") as f:
            f.write(text)
        import os

        os.replace(tmp, dst)
    except OSError as e:
        print(f"error: {dst}: {e.strerror}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
