"""Generated valid OBJ files (element and face runs in random order) and the Mesh fields that compare them."""

from __future__ import annotations

import random


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


FIELDS = ("positions", "texcoords", "normals", "face_start", "corner_vertex", "corner_texcoord", "corner_normal",
          "face_line", "face_group", "face_material")
