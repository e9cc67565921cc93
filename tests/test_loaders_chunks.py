"""OBJ files read in chunks: the mesh must not depend on where the chunks end.

Generated valid OBJ files mix face sizes and corner forms (attributes on some
faces only, empty trailing slots), groups, materials, comments, colours,
negative indices and '\\' continuations, in runs, so that chunk boundaries fall
between runs of one face size and runs of several. Each file is parsed whole,
at chunk sizes down to three bytes, and by the plain line-by-line reader below,
which shares no code with the loader.
"""

import random

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from affinity.loaders.obj import load_obj

CHUNK_SIZES = (4096, 257, 61, 13, 3)


def _number(rng: random.Random, value: float) -> str:
    style = rng.randrange(5)
    if style == 0:
        return f"{value:.6f}"
    if style == 1:
        return repr(value)
    if style == 2:
        return f"{value:.3e}"
    if style == 3:
        return str(round(value))
    return f"{value:.2f}".replace("0.", ".", 1)


def _separator(rng: random.Random, wide: bool) -> str:
    return rng.choice([" ", "\t", "  ", " \t"]) if wide else " "


def generate_obj(rng: random.Random) -> str:
    """A valid OBJ file: element runs and face runs in random order."""
    runs = [("elements", rng.randrange(1, 40)) for _ in range(rng.randrange(1, 4))]
    runs += [("faces", rng.randrange(1, 60)) for _ in range(rng.randrange(1, 6))]
    rng.shuffle(runs)
    runs.insert(0, ("elements", rng.randrange(3, 20)))  # something for the first negative indices
    totals = {"v": 0, "vt": 0, "vn": 0}
    plan = []
    for kind, n in runs:
        if kind == "elements":
            counts = {"v": n, "vt": rng.randrange(0, n + 1) * rng.randrange(2),
                      "vn": rng.randrange(0, n + 1) * rng.randrange(2)}
            for key in totals:
                totals[key] += counts[key]
            plan.append((kind, counts))
        else:
            plan.append((kind, n))
    defined = {"v": 0, "vt": 0, "vn": 0}
    colour_run = rng.random() < 0.3
    lines = []

    def emit(text: str) -> None:
        if rng.random() < 0.05:
            lines.append(rng.choice(["", "# a comment", "s 1", "s off", "   "]))
        lines.append(text)

    def index(key: str) -> str:
        if defined[key] and rng.random() < 0.2:
            return str(-rng.randrange(1, defined[key] + 1))
        return str(rng.randrange(1, totals[key] + 1))

    for kind, what in plan:
        if kind == "elements":
            for key in ("v", "vt", "vn"):
                for _ in range(what[key]):
                    if key == "v":
                        values = [rng.uniform(-5, 5) for _ in range(3)]
                        if colour_run and rng.random() < 0.8:
                            values += [rng.random() for _ in range(3)]
                        elif rng.random() < 0.05:
                            values.append(1.0)  # 'v x y z w'
                    elif key == "vt":
                        values = [rng.random() for _ in range(rng.choice([2, 2, 2, 1, 3]))]
                    else:
                        values = [rng.uniform(-1, 1) for _ in range(3)]
                    emit(" ".join([key] + [_number(rng, x) for x in values]))
                    defined[key] += 1
            continue
        if rng.random() < 0.5:
            emit(rng.choice(["g", "o", "usemtl"]) + " " + rng.choice(["body", "head", "arm_left", "a b", "m1"]))
        sizes = [rng.choice([3, 4, 4, 5, 6])] if rng.random() < 0.5 else [3, 4, 4, 5, 8]
        forms = ["v", "v/vt", "v//vn", "v/vt/vn", "v//", "v/vt/", "v/"]
        forms = [f for f in forms if ("vt" not in f or totals["vt"]) and ("vn" not in f or totals["vn"])]
        run_forms = [rng.choice(forms)] if rng.random() < 0.5 else forms
        wide = rng.random() < 0.2
        for _ in range(what):
            size, form = rng.choice(sizes), rng.choice(run_forms)
            corners = []
            for _ in range(size):
                slots = form.split("/")
                corners.append("/".join(index({"v": "v", "vt": "vt", "vn": "vn"}[s]) if s else "" for s in slots))
            gaps = [_separator(rng, wide) for _ in corners]
            if rng.random() < 0.05:  # continue the statement on the next line
                gaps[1] = " \\\n"
            words = "f" + "".join(gap + corner for gap, corner in zip(gaps, corners))
            emit(words)
    return "\n".join(lines) + rng.choice(["\n", ""])


def reference_parse(text: str) -> dict:
    """The mesh of an OBJ file, one statement at a time, in plain Python."""
    v, vt, vn, colors, has_color = [], [], [], [], False
    face_start, corner = [0], {"v": [], "vt": [], "vn": []}
    face_line, face_group, face_material = [], [], []
    groups, materials = {}, {}
    obj = group = ""
    material = None
    physical = text.split("\n")
    number = 0
    while number < len(physical):
        first = number + 1
        line = physical[number]
        number += 1
        while line.endswith("\\") and number < len(physical):
            line = line[:-1] + " " + physical[number]
            number += 1
        words = line.split()
        words = words[: next((k for k, w in enumerate(words) if w.startswith("#")), len(words))]
        if not words:
            continue
        key, rest = words[0], words[1:]
        if key == "v":
            v.append([float(x) for x in rest[:3]])
            colors.append([float(x) for x in rest[3:6]] if len(rest) >= 6 else [1.0, 1.0, 1.0])
            has_color |= len(rest) >= 6
        elif key == "vt":
            uv = [float(x) for x in rest[:2]]
            vt.append(uv + [0.0] * (2 - len(uv)))
        elif key == "vn":
            vn.append([float(x) for x in rest])
        elif key == "f":
            for word in rest:
                slots = word.split("/") + ["", ""]
                for name, token, elements in zip(("v", "vt", "vn"), slots, (v, vt, vn)):
                    if not token:
                        corner[name].append(-1)
                        continue
                    k = int(token)
                    corner[name].append(len(elements) + k if k < 0 else k - 1)
            face_start.append(face_start[-1] + len(rest))
            face_line.append(first)
            face_group.append(groups.setdefault(group or obj, len(groups)))
            face_material.append(-1 if material is None else materials[material])
        elif key == "o":
            obj, group = " ".join(rest), ""
        elif key == "g":
            group = " ".join(rest)
        elif key == "usemtl":
            material = " ".join(rest)
            materials.setdefault(material, len(materials))
    return {
        "positions": np.array(v, dtype=float).reshape(-1, 3),
        "colors": np.array(colors).reshape(-1, 3) if has_color else None,
        "texcoords": np.array(vt).reshape(-1, 2) if vt else None,
        "normals": np.array(vn).reshape(-1, 3) if vn else None,
        "face_start": np.array(face_start),
        "corner_vertex": np.array(corner["v"], dtype=np.int64),
        "corner_texcoord": np.array(corner["vt"], dtype=np.int64) if vt else None,
        "corner_normal": np.array(corner["vn"], dtype=np.int64) if vn else None,
        "face_line": np.array(face_line, dtype=np.int64),
        "face_group": np.array(face_group, dtype=np.int32),
        "group_names": list(groups) or [""],
        "face_material": np.array(face_material, dtype=np.int32),
        "material_names": list(materials),
    }


FIELDS = ("positions", "texcoords", "normals", "face_start", "corner_vertex", "corner_texcoord", "corner_normal",
          "face_line", "face_group", "face_material")


def assert_same_mesh(mesh, expected: dict, where: str) -> None:
    for name in FIELDS:
        got, want = getattr(mesh, name), expected[name]
        assert (got is None) == (want is None), f"{where}: {name} is {got!r}, expected {want!r}"
        if want is not None:
            np.testing.assert_array_equal(got, want, err_msg=f"{where}: {name}")
    assert mesh.group_names == expected["group_names"], where
    assert mesh.material_names == expected["material_names"], where
    assert (mesh.colors is None) == (expected["colors"] is None), f"{where}: colors"
    if expected["colors"] is not None:
        np.testing.assert_array_equal(mesh.colors, expected["colors"], err_msg=f"{where}: colors")
    mesh.validate()


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(seed=st.integers(0, 2**32 - 1))
def test_chunk_size_never_changes_the_mesh(tmp_path, seed):
    text = generate_obj(random.Random(seed))
    path = tmp_path / f"generated_{seed}.obj"
    path.write_text(text)
    expected = reference_parse(text)
    assert_same_mesh(load_obj(path), expected, "one chunk")
    for size in CHUNK_SIZES:
        assert_same_mesh(load_obj(path, chunk_bytes=size), expected, f"chunks of {size} bytes")


def test_quads_after_a_mixed_chunk_are_kept(tmp_path):
    """The reported case: a part mixing triangles and quads, then a part of triangles only."""
    vertices = "".join(f"v {k} {k % 7} 0\n" for k in range(8))
    mixed = "f 1 2 3 4\nf 1 2 3\n" * 1000
    triangles = "f 2 3 4\n" * 3000
    path = tmp_path / "mixed_then_triangles.obj"
    path.write_text(vertices + mixed + triangles)
    for size in (None, 1 << 12, 100):
        counts = load_obj(path, chunk_bytes=size).counts()
        assert counts == {"faces": 5000, "quads": 1000, "triangles": 4000, "ngons": 0}, size
