"""The vectorized number parser agrees with Python's own float() and int() on every token."""

import random

import numpy as np
import pytest

from affinity.loaders.numbers import PAD, parse_floats, parse_ints

SPECIAL = ["nan", "inf", "-inf", "1e5", "1E-3", ".", "-", "+", "-.", ".5", "5.", "..", "1.2.3", "0", "-0",
           "00000000000000001", "abc", "123456789012345678", "0.1234567890123456789", "9007199254740993"]


def random_token(rng: random.Random) -> str:
    kind = rng.random()
    if kind < 0.5:  # fixed-decimal, the common case
        token = rng.choice(["", "-", "+"]) + str(rng.randint(0, 10 ** rng.randint(0, 9)))
        if rng.random() < 0.8:
            token += "." + "".join(rng.choice("0123456789") for _ in range(rng.randint(0, 10)))
        return token
    if kind < 0.7:  # long digit strings: past what float64 holds exactly
        return rng.choice(["", "-"]) + "".join(rng.choice("0123456789") for _ in range(rng.randint(1, 18)))
    if kind < 0.8:  # junk made of number characters
        return "".join(rng.choice("0123456789.-+eE") for _ in range(rng.randint(1, 20)))
    if kind < 0.9:
        return rng.choice(SPECIAL)
    return repr(rng.uniform(-1e6, 1e6))[: rng.randint(1, 20)]


def python_value(convert, token):
    try:
        return convert(token)
    except ValueError:
        return None


@pytest.mark.parametrize("seed", range(8))
def test_parsers_match_python(seed):
    rng = random.Random(seed)
    tokens = [random_token(rng) for _ in range(2000)]
    separators = [rng.choice([" ", "  ", "\t", "\n", " \n"]) for _ in tokens]
    text = " " * PAD + "".join(t + s for t, s in zip(tokens, separators)) + " " * 16
    shift = seed % 8  # the parser reads 8-byte words: try every alignment of the buffer
    store = np.zeros(len(text) + 16, np.uint8)
    buf = store[shift : shift + len(text)]
    buf[:] = np.frombuffer(text.encode(), np.uint8)
    lengths = np.array([len(t) for t in tokens])
    starts = PAD + np.concatenate([[0], np.cumsum(lengths + [len(s) for s in separators])[:-1]])
    ends = starts + lengths

    values, bad = parse_floats(buf, starts, ends)
    bad = set(bad.tolist())
    for k, token in enumerate(tokens):
        expected = python_value(float, token)
        if expected is None:
            assert k in bad, token
        else:
            assert k not in bad, token
            assert values[k] == expected or (np.isnan(expected) and np.isnan(values[k])), (token, values[k])
            assert np.signbit(values[k]) == np.signbit(expected), token

    # parse_ints names the first token that is no integer (an index error stops the read there),
    # and reads every token before it as Python does.
    integers, bad = parse_ints(buf, starts, ends)
    expected = [python_value(int, token) for token in tokens]
    failing = [k for k, value in enumerate(expected) if value is None or abs(value) >= 2**63]
    assert bad.tolist() == failing[:1]
    valid = np.setdiff1d(np.arange(len(tokens)), failing)
    integers, bad = parse_ints(buf, starts[valid], ends[valid])
    assert len(bad) == 0
    assert integers.tolist() == [expected[k] for k in valid]
