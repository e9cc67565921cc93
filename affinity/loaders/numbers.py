"""Vectorized parsing of ASCII decimal numbers straight from a byte buffer.

The cost of reading a text mesh is number parsing, so tokens are not turned
into Python objects: the (up to) 16 bytes that end each token are loaded as two
little-endian ``uint64`` words and converted with SWAR ("SIMD within a
register") arithmetic, eight digits per word in three multiply-shift steps
(Lemire, "Fast float parsing in practice", 2021, section 5). A fixed-decimal
token ``-12.3456`` becomes the integer ``123456`` and the scale ``10**4``; the
float is their quotient, correctly rounded whenever the digits make an integer
below 2**53 (up to 15 significant digits). Tokens this path cannot take
(exponents, ``nan``, more than 16 characters, 16 significant digits) fall back
to NumPy's own string-to-float cast.

Every step is one NumPy operation over all tokens, so the number of
operations per token is what costs; the word loads are gathers from an aligned
``uint64`` view of the buffer (two aligned words, shifted together), since
NumPy gathers from an unaligned view are several times slower.

Every function here takes ``buf``, a ``uint8`` array holding at least
:data:`PAD` bytes before the first token, and ``starts``/``ends``, the
``(K,) int64`` byte offsets of the tokens (``buf[starts[k]:ends[k]]``).
"""

from __future__ import annotations

import numpy as np

#: Bytes every buffer must hold before its first token (the two words read back).
PAD = 16

_U = np.uint64
_ZEROS = _U(0x3030303030303030)  # eight ASCII '0'
_DOT_DIGITS = _U(0x1E1E1E1E1E1E1E1E)  # eight '.' after subtracting '0' (XOR 0x30)
_HIGH_NIBBLES = _U(0xF0F0F0F0F0F0F0F0)
_SIXES = _U(0x0606060606060606)
_LOW7 = _U(0x7F7F7F7F7F7F7F7F)
_HIGH_BITS = _U(0x8080808080808080)
_ONES = (1 << 64) - 1
#: Longest token (after its sign) the fast paths take.
_WIDEST = 16
#: ``_KEEP_LO[n]`` / ``_KEEP_HI[n]``: the bytes of the last / second-last word
#: that belong to a token of ``n`` characters (the word ends where the token ends,
#: so its first characters are the high word's last bytes). ``n`` is clipped to 17.
_KEEP_LO = np.array([_ONES << 8 * max(8 - n, 0) & _ONES for n in range(_WIDEST + 2)], dtype=np.uint64)
_KEEP_HI = np.array([_ONES << 8 * min(max(16 - n, 0), 8) & _ONES for n in range(_WIDEST + 2)], dtype=np.uint64)
#: ``_SCALE[index + 256 * negative]`` divides the digits of a token into its value;
#: ``index`` comes from :func:`_dot_index`: 0 without a dot, ``127 + k`` for a dot in
#: byte ``k`` of the low word, ``135 + k`` in byte ``k`` of the high word. A dot
#: leaves one trailing zero digit (see :func:`_close_dot`), hence the extra 10.
_SCALE = np.ones(512)
_SCALE[127:135] = 10.0 ** (8 - np.arange(8))
_SCALE[135:143] = 10.0 ** (16 - np.arange(8))
_SCALE[256:] = -_SCALE[:256]
_MINUS, _PLUS = ord("-"), ord("+")
#: Digits below this make a float64 exactly (2**53).
_EXACT = _U(1 << 53)
#: The largest magnitude a coordinate or attribute value may have. The lint's arithmetic of
#: highest degree is the squared length of the cross product of two edges: with every
#: value within +-M an edge is at most 2 sqrt(3) M long and that square at most 144 M^4,
#: finite (below 1.8e308) for M below 1.06e77; 1e75 leaves a factor of 100 for the terms
#: around it. Attributes enter at degree 2 (times a texture size of up to 2^16), well
#: within that. A file with a larger value is unreadable (Q901 at its line), not a storm
#: of overflow warnings.
LARGEST = 1e75


def out_of_range(values: np.ndarray) -> np.ndarray:
    """Bool, shaped like ``values``: NaN, infinite, or of magnitude above :data:`LARGEST`.

    >>> out_of_range(np.array([1e75, -1e76, np.inf, np.nan, 0.0])).tolist()
    [False, True, True, True, False]
    """
    return ~(np.abs(values) <= LARGEST)


def words(buf: np.ndarray) -> np.ndarray:
    """(n - 7,) uint64 view of ``buf``: element ``i`` is bytes ``i..i+7`` (no copy).

    Gathers from this unaligned view are slow; :class:`WordReader` is the fast way.
    """
    return np.ndarray((len(buf) - 7,), dtype="<u8", buffer=buf, strides=(1,))


class WordReader:
    """Load the eight bytes before given offsets of ``buf`` as little-endian uint64.

    ``WordReader(buf)(ends)`` is ``words(buf)[ends - 8]``, computed from two
    gathers of an aligned view (a NumPy gather from an unaligned view takes
    several times as long). Offsets must be at least 8.
    """

    def __init__(self, buf: np.ndarray):
        if len(buf) < 32:  # too short for two aligned words and a margin: pad a copy
            buf = np.concatenate([buf, np.zeros(32, np.uint8)])
        self.buf = buf
        self.offset = -buf.ctypes.data % 8
        count = (len(buf) - self.offset) // 8
        self.aligned = buf[self.offset : self.offset + 8 * count].view("<u8")
        #: Words ending beyond this offset are read from the unaligned view.
        self.limit = self.offset + 8 * (count - 1)
        #: No token ends in the last 16 bytes (chunks end in spaces): none is that late.
        self.tail_free = bool((buf[-16:] <= 32).all())

    def __call__(self, ends: np.ndarray, back: int = 8) -> np.ndarray:
        """(K,) uint64 words of bytes ``ends - back .. ends - back + 7``."""
        start = ends - (back + self.offset)
        index = start >> 3
        shift = (start & 7).view(np.uint64)
        shift <<= _U(3)
        low = self.aligned.take(index, mode="clip")
        low >>= shift
        high = self.aligned[1:].take(index, mode="clip")
        high <<= _U(64) - shift  # a shift by 64 gives 0 in NumPy
        low |= high
        if not self.tail_free and ends.size and ends.max() - back + 8 > self.limit:  # the buffer's last bytes
            late = np.flatnonzero(ends - back + 8 > self.limit)
            low.reshape(-1)[late] = words(self.buf)[ends.reshape(-1)[late] - back]
        return low


def eight_digits(x: np.ndarray) -> np.ndarray:
    """(K,) uint64 words of eight digit values 0..9 (first digit in the lowest byte)
    -> their values, in place (Lemire 2021, multiply-shift form)."""
    x *= _U(10 << 8 | 1)
    x >>= _U(8)
    x &= _U(0x00FF00FF00FF00FF)
    x *= _U(100 << 16 | 1)
    x >>= _U(16)
    x &= _U(0x0000FFFF0000FFFF)
    x *= _U(10000 << 32 | 1)
    x >>= _U(32)
    return x


def _not_digits(x: np.ndarray) -> np.ndarray:
    """(K,) uint64, nonzero where some byte of ``x`` is not a digit value 0..9."""
    y = x + _SIXES
    y |= x
    y &= _HIGH_NIBBLES
    return y


def _dot_bit(d: np.ndarray) -> np.ndarray:
    """(K,) uint64 ``1 << 8k`` for the first (lowest) byte ``k`` of ``d`` that holds
    a '.' (0x1E once '0' is XORed away), 0 where there is none."""
    y = d ^ _DOT_DIGITS
    z = y & _LOW7
    z += _LOW7
    z |= y
    np.invert(z, out=z)
    z &= _HIGH_BITS  # bit 7 of every byte of y that is zero
    lowest = np.negative(z)
    lowest &= z
    lowest >>= _U(7)
    return lowest


def _close_dot(d: np.ndarray, below: np.ndarray, carry: np.ndarray | None = None) -> np.ndarray:
    """Remove the dot from digit word ``d`` in place: the bytes above the dot
    (later characters) move down one byte, the last byte becomes 0 (or the
    first byte of ``carry``, the next word). ``below`` keeps the bytes before the
    dot (``dot_bit - 1``; all ones without a dot)."""
    shifted = d >> _U(8)
    if carry is not None:
        shifted |= carry << _U(56)
    shifted &= ~below
    d &= below
    d |= shifted
    return d


def _dot_index(dot_lo: np.ndarray, dot_hi: np.ndarray | None) -> np.ndarray:
    """(K,) int64 row of :data:`_SCALE` for the dot bits of the two words: the
    float exponent of ``dot_lo + dot_hi * 2**64`` (a power of two or 0) read off its bits."""
    position = dot_lo.astype(np.float64)
    if dot_hi is not None:
        high = dot_hi.astype(np.float64)
        high *= 2.0**64
        position += high
    index = position.view(np.int64)
    index >>= 55
    return index


def _fixed_decimals(buf, starts, ends, allow_dot):
    """Digits of tokens ``[+-]digits[.digits]`` of at most 16 characters after the sign.

    Returns ``mantissa (K,) uint64`` (the digits as one integer, with one
    trailing 0 after a dot), ``scale_index (K,) int64`` (row of :data:`_SCALE`,
    sign included; None without ``allow_dot``), ``negative (K,) bool`` and
    ``ok (K,) bool``; where ``ok`` is False the others are meaningless.
    """
    read = WordReader(buf)
    first = buf[starts]
    negative = first == _MINUS
    length = ends - starts
    length -= negative | (first == _PLUS)
    np.minimum(length, _WIDEST + 1, out=length)
    lo = read(ends)
    lo ^= _ZEROS
    lo &= _KEEP_LO[length]
    wide = bool(length.max(initial=0) > 8)
    hi = None
    if wide:
        hi = read(ends, 16)
        hi ^= _ZEROS
        hi &= _KEEP_HI[length]
    scale_index = None
    if allow_dot:
        dot_lo = _dot_bit(lo)
        below_lo = dot_lo - _U(1)
        if wide:
            dot_hi = _dot_bit(hi)
            below_hi = dot_hi - _U(1)
            _close_dot(hi, below_hi, carry=lo)
            # A dot in the high word moves every byte of the low word down.
            below_lo &= np.negative(below_hi >> _U(63))
            scale_index = _dot_index(dot_lo, dot_hi)
        else:
            scale_index = _dot_index(dot_lo, None)
        _close_dot(lo, below_lo)
        scale_index += negative * 256
    bad = _not_digits(lo)
    mantissa = eight_digits(lo)
    if wide:
        bad |= _not_digits(hi)
        mantissa += eight_digits(hi) * _U(100000000)
    ok = bad == 0
    if wide:
        ok &= mantissa < _EXACT
    if length.min(initial=1) < 2 or length.max(initial=0) > _WIDEST:
        # No digit at all: '', '-', '.', '-.'; or too long for two words.
        odd = np.flatnonzero((length < 2) | (length > _WIDEST))
        odd_length = length.reshape(-1)[odd]
        empty = (odd_length == 0) | (odd_length > _WIDEST)
        if allow_dot:
            empty |= (odd_length == 1) & (scale_index.reshape(-1)[odd] % 256 != 0)
        ok.reshape(-1)[odd[empty]] = False
    return mantissa, scale_index, negative, ok


def _token_strings(buf, starts, ends) -> np.ndarray:
    """(K,) fixed-width bytes array of the tokens (for the slow fallback)."""
    width = int((ends - starts).max())
    window = np.lib.stride_tricks.sliding_window_view(np.append(buf, np.zeros(width, np.uint8)), width)
    text = window[starts].copy()
    text[np.arange(width) >= (ends - starts)[:, None]] = 0
    return text.view(f"S{width}").ravel()


def parse_floats(buf, starts, ends, finite=False):
    """Parse decimal tokens as float64.

    ``starts`` and ``ends`` may have any shape (views of a token block, say).

    Returns
    -------
    values : float64, shaped like ``starts``
        NaN/inf only where the token spells them (``nan``, ``inf``, ``1e999``).
    bad : (n,) int64
        Flat indices of the tokens that are not numbers (``values`` there is NaN),
        and with ``finite`` also of those that are NaN, infinite or beyond :data:`LARGEST`.
    """
    mantissa, scale_index, _, ok = _fixed_decimals(buf, starts, ends, allow_dot=True)
    values = mantissa.view(np.int64).astype(np.float64)  # < 2**53 where ok: exact
    values /= _SCALE[scale_index]
    if ok.all():  # only slow tokens can be NaN, infinite or large (the fast ones are below 1e16)
        return values, np.zeros(0, dtype=np.int64)
    slow = np.flatnonzero(~ok)
    flat = values.reshape(-1)
    flat[slow], failed = _slow_floats(buf, starts.reshape(-1)[slow], ends.reshape(-1)[slow])
    if finite:
        failed |= out_of_range(flat[slow])
    return values, slow[failed]


def _slow_floats(buf, starts, ends):
    """Tokens the fast path cannot take: ``values (K,) float64`` and ``failed (K,) bool``
    (not a number at all; NaN there)."""
    strings = _token_strings(buf, starts, ends)
    try:
        return strings.astype(np.float64), np.zeros(len(strings), dtype=bool)
    except ValueError:
        values = np.full(len(strings), np.nan)
        failed = np.zeros(len(strings), dtype=bool)
        for k, text in enumerate(strings):
            try:
                values[k] = float(text)
            except ValueError:
                failed[k] = True
        return values, failed


def parse_ints(buf, starts, ends):
    """Parse signed decimal integer tokens.

    Unsigned tokens of up to eight digits (every mesh index below 10**8) take
    one word and no sign handling; the rest go through the signed two-word path,
    and only tokens that fail both (not integers, or longer than 16
    characters) are converted one by one.

    ``starts`` and ``ends`` may have any shape.

    Returns
    -------
    values : int64, shaped like ``starts``
    bad : (0,) or (1,) int64
        Flat index of the first token that is not an integer (``values`` is 0 there, and
        unspecified for the long tokens after it).
    """
    length = ends - starts
    np.minimum(length, 9, out=length)
    digits = WordReader(buf)(ends)
    digits ^= _ZEROS
    digits &= _KEEP_LO[length]
    ok = _not_digits(digits) == 0
    ok &= length <= 8
    values = eight_digits(digits).view(np.int64)
    if ok.all():
        return values, np.zeros(0, dtype=np.int64)
    rest = np.flatnonzero(~ok)
    starts, ends = starts.reshape(-1)[rest], ends.reshape(-1)[rest]
    mantissa, _, negative, signed_ok = _fixed_decimals(buf, starts, ends, allow_dot=False)
    signed = mantissa.view(np.int64)
    np.negative(signed, out=signed, where=negative)
    bad = []
    for k in np.flatnonzero(~signed_ok):  # only tokens of more than 16 characters or not integers at all
        try:
            signed[k] = int(bytes(buf[starts[k] : ends[k]]))
        except (ValueError, OverflowError):
            bad.append(rest[k])
            signed[k] = 0
            break  # the first is the error; junk of millions of tokens is not read one by one
    values.reshape(-1)[rest] = signed
    return values, np.array(bad, dtype=np.int64)


def out_of_range_reason(value) -> str:
    """The reason a file with the finite ``value`` beyond :data:`LARGEST` is unreadable.

    >>> print(out_of_range_reason(1e300))
    value 1e+300 is out of range: magnitudes above 1e+75 overflow the lint's arithmetic
    """
    return f"value {value} is out of range: magnitudes above {LARGEST:g} overflow the lint's arithmetic"
