"""OBJ texts that must fail to load, with the line and words of their error (tests of the OBJ reader)."""

SQUARE = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"  # lines 1-4

#: Statements after the square's four vertices that are wrong on their own line (5), by the words of the error.
BAD_FIFTH_LINE = {
    "corners": ["f 1 2", "f"], "index": ["f 1 0 2", "f 1 2 3.5"], "out of range": ["f 1 2 9"],
    "texture coordinate index out of range": ["f 1/1 2/1 3/1"], "numbers": ["vn 0 1"],
    "malformed": ["f 1/1/1/1 2 3", "f 1/1// 2 3", "f /1 2 3", "f 1///2 2 3"], "statement": ["1.0 2.0 3.0"],
}
#: Whole files whose error is on a later or an earlier line: (text, line, words).
BAD_OTHER_LINE = [
    (SQUARE + "f 1 2 3\nf -5 1 2\n", 6, "out of range"), (SQUARE + "vt 0 0\nf 1/1 2 3\n", 6, "mix"),
    (SQUARE + "vt 0 0\nf 1//1 2//1 3//1\n", 6, "normal index out of range"), ("v 0 0\n", 1, "numbers"),
    *((f"v 0 0 0\nv 1 0 {bad}\nv 1 1 0\nf 1 2 3\n", 2, "finite") for bad in ("nan", "inf", "1e999")),
    ("v 0 0 0\nv 1 0 x\nv 1 1 0\nf 1 2 3\n", 2, "not a number"),
    ("v 0 0 0 2 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n", 1, "colour"),
]
