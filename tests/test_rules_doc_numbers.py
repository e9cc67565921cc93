"""Every number a rule page prints is accounted for: a value ``affinity check`` measures is derived from a
closed form, recomputed here from the page's own example with exact fractions or 40-digit mpmath (never
with the package's measures), and compared with what ``affinity check`` prints for the example (its JSON
value to 1e-12, its text line to the digits printed); any other number is a setting, a unit, a constant
of a formula printed beside it, or a location, and says so in :data:`NUMBERS`.

The page's numbers are read from its prose (summary, What it does, Why it matters, How to fix) and from
the lines its example prints (the example files themselves are input, the References citations).
:data:`NUMBERS` must list exactly the numbers a page prints: a new number on a page fails here until it
is derived or labelled (a value with no closed form is labelled on the page and here as a snapshot of a
named affinity version).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from fractions import Fraction

import mpmath
import pytest
from helpers.cli import run

from affinity.rules import RULES, UNREADABLE

mpmath.mp.dps = 40
PAGES = {**RULES, UNREADABLE.code: UNREADABLE}

#: A number as pages write them: ``-1``, ``.01``, ``175.7``, ``1e-09``, ``1/255``, ``1024x1024``; not
#: one inside a word or a name (``n0``, ``Q101``, ``3D-Print``).
NUMBER = re.compile(r"(?<![\w.])-?(?:\d+(?:\.\d+)?|\.\d+)(?:e-?\d+)?(?:[/x]\d+(?:\.\d+)?)?(?![\w.]*[A-Za-z_])")
#: The location around a printed line: ``example.obj:10:1: `` (``example.obj:5: `` for Q901) and `` [face 0]``.
LOCATION = re.compile(r"^example\.obj:(?P<line>\d+):(?:(?P<column>\d+):)? |\s\[face (?P<face>\d+)\]$", re.M)
#: The measured value in a printed line: ``(175.7 vs 0.5 texels)``, ``(0.5 folded fraction)``, ``(4 vertices)``.
PRINTED_VALUE = re.compile(r"\((?P<value>-?\d[\d.e+-]*)(?: vs | [a-z])")


@dataclass(frozen=True)
class Closed:
    """A value derived from a closed form: ``value`` is that form evaluated exactly (Fraction) or to
    40 digits (mpmath) from the example's data."""

    value: Fraction | mpmath.mpf

    def shown_as(self, printed: str) -> bool:
        """Whether ``printed`` is ``value``: rounded to its decimals where it has a decimal point
        (``175.7``), else exactly (``60``, ``1/2``, ``-1``), to mpmath's 40 digits."""
        number = Fraction(printed)
        error = abs(mpmath.mpf(number.numerator) / number.denominator - mpmath.mpf(self.value))
        decimals = len(printed.split(".")[1]) if "." in printed else None
        return error <= (mpmath.mpf(10) ** -decimals / 2 if decimals is not None else mpmath.mpf(10) ** -30)


def example_data(text: str) -> dict[str, list]:
    """The example OBJ as exact numbers: ``v`` (positions), ``color``, ``vt``, ``vn`` (lists of Fraction
    tuples) and ``f`` (lists of 0-based position indices) - a reader independent of the package's."""
    data: dict[str, list] = {"v": [], "color": [], "vt": [], "vn": [], "f": []}
    for line in text.splitlines():
        keyword, *words = line.split() or ["#"]
        if keyword == "v":
            data["v"].append(tuple(Fraction(w) for w in words[:3]))
            if len(words) == 6:
                data["color"].append(tuple(Fraction(w) for w in words[3:]))
        elif keyword in ("vt", "vn"):
            data[keyword].append(tuple(Fraction(w) for w in words))
        elif keyword == "f":
            data["f"].append([int(w.split("/")[0]) - 1 for w in words])
    return data


def minus(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    """3-D cross product; 2-D vectors read as z = 0."""
    a, b = (tuple(a) + (0,) * (3 - len(a)), tuple(b) + (0,) * (3 - len(b)))
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def norm(a):
    return mpmath.sqrt(mpmath.mpf(dot(a, a)))


def alternating(corners):
    """c0 - c1 + c2 - c3: zero exactly when the corner values are an affine image of a parallelogram."""
    return tuple(a - b + c - d for a, b, c, d in zip(*corners))


def degrees_between(a, b):
    return mpmath.degrees(mpmath.atan2(norm(cross(a, b)), dot(a, b)))


def quad(code: str, table: str = "v") -> list[tuple]:
    """The corner values (``table``: ``v``, ``color``, ``vt`` or ``vn``) of the first face of ``code``'s
    example, indexed as OBJ does: ``f v/vt/vn``."""
    text = PAGES[code].example
    face = next(line for line in text.splitlines() if line.startswith("f "))
    slot = {"vt": 1, "vn": 2}.get(table, 0)
    return [example_data(text)[table][int(w.split("/")[slot]) - 1] for w in face.split()[1:]]


def uv_relative_area(uv) -> Fraction:
    """Signed area (shoelace) over the squared longest edge."""
    area = sum(cross(uv[k], uv[(k + 1) % 4])[2] for k in range(4)) / 2
    return area / max(dot(e, e) for e in (minus(uv[(k + 1) % 4], uv[k]) for k in range(4)))


def q101_trapezoid():
    """Q101: side ratio r and (1 - r) / (1 + sqrt r)^2 of the 1024-texel width (the page's closed form); the
    centre shift |R| / (4 max |T|), R = sum_k (-1)^k T_k uv_k (design.md), an eighth of the width here."""
    p, uv = quad("Q101"), quad("Q101", "vt")
    r = Fraction(p[2][0] - p[3][0]) / (p[1][0] - p[0][0])
    T = [cross(minus(p[(k + 2) % 4], p[(k + 1) % 4]), minus(p[(k + 3) % 4], p[(k + 1) % 4]))[2] for k in range(4)]
    R = tuple(sum((-1) ** k * T[k] * uv[k][axis] for k in range(4)) for axis in range(2))
    centre = mpmath.sqrt(dot(R, R)) / (4 * max(abs(T[1]), abs(T[3])))
    return r, 1024 * (1 - r) / (1 + mpmath.sqrt(r)) ** 2, 1024 * centre


def q103_turn():
    """Q103: atan2(|n0 - n1 + n2 - n3|, |n0 + n1 + n2 + n3|) of the unit normals, and the page's simplification."""
    unit = [tuple(mpmath.mpf(x) / norm(n) for x in n) for n in quad("Q103", "vn")]
    turn = mpmath.degrees(mpmath.atan2(norm(alternating(unit)), norm(tuple(map(sum, zip(*unit))))))
    simplified = mpmath.degrees(mpmath.atan((19 - 8 * mpmath.sqrt(5)) / mpmath.sqrt(41)))
    return turn, simplified


def q202_normal(a: int, b: int, c: int) -> tuple:
    """Q202: the normal of the example's triangle (p_a, p_b, p_c), exactly."""
    p = quad("Q202")
    return cross(minus(p[b], p[a]), minus(p[c], p[a]))


def q202_folds():
    """Q202: the dihedral angle of the split along 0-2 (triangles 012, 023) and 1-3 (123, 130)."""
    return (degrees_between(q202_normal(0, 1, 2), q202_normal(0, 2, 3)),
            degrees_between(q202_normal(1, 2, 3), q202_normal(1, 3, 0)))


def q203_reflex():
    """Q203: 360 degrees less the angle between the edges that leave the reflex corner (the one turning clockwise)."""
    p = quad("Q203")
    k = next(k for k in range(4) if cross(minus(p[k], p[k - 1]), minus(p[(k + 1) % 4], p[k]))[2] < 0)
    return 360 - degrees_between(minus(p[k - 1], p[k]), minus(p[(k + 1) % 4], p[k]))


def q204_folded():
    """Q204: sum of |T_k| over clockwise corner turns / sum of |T_k|, T_k = (p_k - p_k-1) x (p_k+1 - p_k)."""
    p = quad("Q204")
    turns = [cross(minus(p[k], p[k - 1]), minus(p[(k + 1) % 4], p[k]))[2] for k in range(4)]
    return Fraction(sum(-t for t in turns if t < 0), sum(abs(t) for t in turns))


def q201_smallest_triangle():
    """Q201: the smallest of the four corner triangles' areas over the squared longest edge."""
    p = quad("Q201")
    areas = [norm(cross(minus(p[k - 1], p[k]), minus(p[(k + 1) % 4], p[k]))) / 2 for k in range(4)]
    return min(areas) / max(dot(e, e) for e in (minus(p[(k + 1) % 4], p[k]) for k in range(4)))


R, Q101_WORST, Q101_CENTRE = q101_trapezoid()
Q202_02, Q202_13 = q202_folds()
def q106_limit_u() -> Fraction:
    """The limit u of the example's shared edge where it meets the boundary: the smooth boundary rule's limit
    (u_prev + 4 u + u_next) / 6 along the boundary (Catmull-Clark's B-spline boundary curve)."""
    u = [vt[0] for vt in example_data(RULES["Q106"].example)["vt"]]
    return (u[0] + 4 * u[1] + u[2]) / 6


def q106_drift() -> Fraction:
    """The example's drift in uv units: the limit u minus the cage's (the largest over the quads' samples)."""
    return q106_limit_u() - example_data(RULES["Q106"].example)["vt"][1][0]


THRESHOLD = "the rule's default threshold (a setting, shown by the page's Level line)"
VISIBLE = "the visibility threshold (setting levels.CODE), shown by the page's Level line"
CONSTANT = "a constant of the closed form printed beside it"

#: Every number each page prints -> its closed form, or why it needs none.
NUMBERS: dict[str, dict[str, Closed | str]] = {
    "Q101": {
        "175.7": Closed(Q101_WORST), "128": Closed(Q101_CENTRE), "1/2": Closed(R),
        "0.5": THRESHOLD, "2": VISIBLE + "; " + CONSTANT, "1": CONSTANT, "1/255": "the unit of the visible reading",
        ".01": "the paper's tolerance (Bloomenthal 2022, Listing 3)",
        "1024": "the texture-size setting's default", "1024x1024": "the texture-size setting's default",
    },
    "Q102": {
        "110.4": Closed(255 * norm(alternating(quad("Q102", "color"))) / 4),
        "2/255": THRESHOLD, "8/255": VISIBLE, "1/255": "the unit", "255": "the unit (1/255 steps)",
        "-1": "a component of the example's c0 - c1 + c2 - c3 = (-1, 1, 1), checked below",
        "0": "the colour range [0, 1]", "1": "the colour range [0, 1]; a component of c0 - c1 + c2 - c3",
        "3": CONSTANT, "4": CONSTANT,
    },
    "Q103": {
        "9.847": Closed(q103_turn()[0]), "2": THRESHOLD, "8": VISIBLE + "; " + CONSTANT,
        "19": CONSTANT, "41": CONSTANT, "5": CONSTANT,
    },
    "Q106": {
        "102.4": Closed(1024 * q106_drift()), "0.1": Closed(q106_drift()), "0.3": Closed(q106_limit_u()),
        "0.2": Closed(example_data(RULES["Q106"].example)["vt"][1][0]),
        "0": Closed(example_data(RULES["Q106"].example)["vt"][0][0]),
        "1": THRESHOLD + "; the u at the edge's far end, " + CONSTANT, "4": CONSTANT, "6": CONSTANT,
        "5": "the samples a side of a quad refined twice (2^2 + 1)",
        "1024": "the texture-size setting's default", "1024x1024": "the texture-size setting's default",
    },
    "Q201": {"0": Closed(q201_smallest_triangle()), "1e-09": THRESHOLD},
    "Q202": {
        "60": Closed(max(Q202_02, Q202_13)), "54.74": Closed(Q202_13),
        "1/2": Closed(mpmath.cos(mpmath.radians(Q202_02))),
        "45": THRESHOLD, "2": "a corner of the diagonal 0-2", "3": "a corner of the diagonal 1-3; " + CONSTANT,
        **dict.fromkeys(("-1", "0", "1"), "a coordinate of the split's triangle normals (0, -1, 1) and (-1, 0, 1), "
                        "checked in test_the_pages_simplified_forms_equal_the_general_ones; a corner of 1-3"),
    },
    "Q203": {
        "233.1": Closed(q203_reflex()),
        "1/3": "tan of the edges' angle to the axes: 270 - 2 atan(1/3) is checked against the general form",
        "270": CONSTANT, "2": CONSTANT, "180": THRESHOLD,
    },
    "Q204": {"0.5": Closed(q204_folded()), "1/2": Closed(q204_folded())},
    "Q205": {
        "4": Closed(Fraction(len(example_data(RULES["Q205"].example)["v"]))),
        "-1": "the face a file-wide finding points at", "1": "the line a file-wide finding points at",
    },
    "Q301": {"0": Closed(abs(uv_relative_area(quad("Q301", "vt")))), "1e-09": THRESHOLD},
    "Q302": {"-1": Closed(uv_relative_area(quad("Q302", "vt")))},
    "Q902": {
        "256": Closed(Fraction(1024, 4)), "1024": "the texture-size setting's default, and 4096 / 4",
        "4096": "a texture size, for the example",
    },
    "Q901": {
        "5": Closed(Fraction(UNREADABLE.example.splitlines().index(next(
            line for line in UNREADABLE.example.splitlines() if line.startswith("f "))) + 1)),
        "4": Closed(Fraction(max(example_data(UNREADABLE.example)["f"][0]) + 1)),
        "3": Closed(Fraction(len(example_data(UNREADABLE.example)["v"]))), "2": "the exit code for unreadable input",
    },
}


def page_numbers(code: str) -> set[str]:
    """The numbers of ``code``'s page: its prose and the lines its example prints, locations left out."""
    rule = PAGES[code]
    return set(NUMBER.findall("\n".join([rule.summary, rule.what, rule.why, rule.fix,
                                         LOCATION.sub(" ", rule.example_output)])))


def test_the_number_pattern_reads_what_pages_write():
    text = "(175.7 vs 0.5 texels) at .01, 1e-09, r = 1/2, -1, 1024x1024, n0, Q101, 3D-Print, 0-2, arccos(1/sqrt 3)"
    assert NUMBER.findall(text) == ["175.7", "0.5", ".01", "1e-09", "1/2", "-1", "1024x1024", "0", "2", "1", "3"]


@pytest.mark.parametrize("code", PAGES)
def test_every_number_on_the_page_is_derived_or_labelled(code):
    numbers = NUMBERS[code]
    assert page_numbers(code) == set(numbers), "derive the new number in NUMBERS, or drop the stale entry"
    for printed, source in numbers.items():
        if isinstance(source, Closed):
            assert source.shown_as(printed), f"{code}: {printed} is not {mpmath.nstr(source.value, 12)}"
        else:
            assert len(source) > 5


@pytest.mark.parametrize("code", [code for code in RULES if PRINTED_VALUE.search(RULES[code].example_output)])
def test_what_check_prints_for_the_example_is_its_closed_form(code, tmp_path):
    """The JSON value to 1e-12 and the text line to the digits it prints, against the page's closed form."""
    (tmp_path / "example.obj").write_text(RULES[code].example)
    flags = RULES[code].example_flags
    result = run("check", "--select", "ALL", "--format", "json", *flags, "example.obj", cwd=tmp_path)
    findings = json.loads(result.stdout)["findings"]
    assert len(findings) == RULES[code].example_output.count("\n")  # one a line the page prints
    printed = PRINTED_VALUE.search(RULES[code].example_output)["value"]
    closed = NUMBERS[code][printed]
    assert isinstance(closed, Closed), f"{code}'s printed value {printed} has no closed form"
    for finding in findings:
        assert abs(finding["value"] - closed.value) <= 1e-12 * max(1, abs(closed.value))
    text = run("check", "--select", "ALL", *flags, "example.obj", cwd=tmp_path).stdout
    assert closed.shown_as(PRINTED_VALUE.search(text)["value"])


def test_q101_centre_shift_is_an_eighth_of_the_width(tmp_path):
    """The page's prose: --measure centre on the example prints 128 texels, |R| / (4 max |T|) of 1024."""
    assert Q101_CENTRE == 128 and R == Fraction(1, 2)
    (tmp_path / "example.obj").write_text(RULES["Q101"].example)
    result = run("check", "--measure", "centre", "--format", "json", "example.obj", cwd=tmp_path)
    finding, = json.loads(result.stdout)["findings"]
    assert abs(finding["value"] - 128) <= 1e-12 * 128


def test_the_pages_simplified_forms_equal_the_general_ones():
    """Q103's atan((19 - 8 sqrt 5) / sqrt 41), Q202's arccos(1/2) and arccos(1/sqrt 3), Q203's 270 - 2 atan(1/3)
    and Q102's |(-1, 1, 1)| / 4 are the general closed forms evaluated on the examples."""
    turn, simplified = q103_turn()
    assert abs(turn - simplified) < mpmath.mpf(10) ** -35
    assert abs(Q202_02 - 60) < mpmath.mpf(10) ** -35
    assert abs(Q202_13 - mpmath.degrees(mpmath.acos(1 / mpmath.sqrt(3)))) < mpmath.mpf(10) ** -35
    assert abs(q203_reflex() - (270 - 2 * mpmath.degrees(mpmath.atan(mpmath.mpf(1) / 3)))) < mpmath.mpf(10) ** -35
    assert q202_normal(0, 1, 2) == (0, -1, 1) and q202_normal(0, 2, 3) == (-1, 0, 1)
    assert alternating(quad("Q102", "color")) == (-1, 1, 1)
    corners = quad("Q102")
    assert alternating(corners) == (0, 0, 0), "the closed form |c0 - c1 + c2 - c3| / 4 holds on parallelograms"


@pytest.mark.parametrize("code", PAGES)
def test_the_printed_location_is_where_the_example_has_it(code):
    """The line is the example's face line (the mtllib line for Q902, line 1 for a file without faces);
    column 1; face 0, the example's only face."""
    example = PAGES[code].example.splitlines()
    keyword = "mtllib" if code == "Q902" else "f"
    faces = [n for n, line in enumerate(example, start=1) if line.split()[:1] == [keyword]]
    expected_line = faces[0] if faces else 1
    location = LOCATION.search(PAGES[code].example_output)
    assert int(location["line"]) == expected_line
    assert location["column"] == (None if code == UNREADABLE.code else "1")
    face = LOCATION.search(PAGES[code].example_output.rstrip("\n"), location.end())
    has_face = code not in ("Q205", "Q902", UNREADABLE.code)
    assert (face is not None and face["face"] == "0") if has_face else face is None
