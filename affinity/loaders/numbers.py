"""Vectorized parsing of ASCII decimal numbers straight from a byte buffer.

The cost of reading a text mesh is number parsing, so tokens are not turned
into Python objects: the (up to) 16 bytes that end each token are loaded as two
little-endian ``uint64`` words and converted with SWAR ("SIMD within a
register") arithmetic, eight digits per word in three multiply-shift steps
(Lemire, "Fast float parsing in practice", 2021, section 5). A fixed-decimal
token ``-12.3456`` becomes the integer ``123456`` and the scale ``10**4``; the
float is their quotient, correctly rounded for up to 15 significant digits
(within one ulp up to 16). Tokens this path cannot take (exponents, ``nan``,
more than 16 characters) fall back to NumPy's own string-to-float cast.

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
_DOTS = _U(0x2E2E2E2E2E2E2E2E)  # eight ASCII '.'
_HIGH_NIBBLES = _U(0xF0F0F0F0F0F0F0F0)
_SIXES = _U(0x0606060606060606)
_LOW7 = _U(0x7F7F7F7F7F7F7F7F)
_HIGH_BITS = _U(0x8080808080808080)
_ONES = _U(0xFFFFFFFFFFFFFFFF)
#: ``_KEEP[k]`` keeps bytes ``k..7`` of a word (bytes below ``k`` are not the token's).
_KEEP = np.array([_ONES << _U(8 * k) if k < 8 else 0 for k in range(9)], dtype=np.uint64)
#: ``_SCALE[k + 17 * negative]`` divides a mantissa with ``k`` fraction digits.
_SCALE = np.concatenate([10.0 ** np.arange(17), -(10.0 ** np.arange(17))])
_MINUS, _PLUS = ord("-"), ord("+")


def words(buf: np.ndarray) -> np.ndarray:
    """(n - 7,) uint64 view of ``buf``: element ``i`` is bytes ``i..i+7`` (no copy)."""
    return np.ndarray((len(buf) - 7,), dtype="<u8", buffer=buf, strides=(1,))


def _eight_digits(x: np.ndarray) -> np.ndarray:
    """(K,) uint64 words of eight ASCII digits (first digit in the lowest byte) -> values."""
    x = x - _ZEROS
    x = (x * _U(10) + (x >> _U(8))) & _U(0x00FF00FF00FF00FF)
    x = (x * _U(100) + (x >> _U(16))) & _U(0x0000FFFF0000FFFF)
    return (x * _U(10000) + (x >> _U(32))) & _U(0xFFFFFFFF)


def _all_digits(x: np.ndarray) -> np.ndarray:
    """(K,) bool: every byte of the word is an ASCII digit."""
    return ((x & _HIGH_NIBBLES) == _ZEROS) & (((x + _SIXES) & _HIGH_NIBBLES) == _ZEROS)


def _dot_bytes(x: np.ndarray) -> np.ndarray:
    """(K,) uint64 with bit 7 set in exactly the bytes of ``x`` that are '.'."""
    y = x ^ _DOTS
    return ~(((y & _LOW7) + _LOW7) | y) & _HIGH_BITS


def _single_bit(z: np.ndarray) -> np.ndarray:
    return (z & (z - _U(1))) == 0


def _up_to_dot(z: np.ndarray) -> np.ndarray:
    """Mask of the bytes at and below the (single) dot byte marked in ``z``; 0 without one."""
    mask = ((z >> _U(7)) << _U(8)) - _U(1)
    mask[z == 0] = 0
    return mask


def _dot_byte(z: np.ndarray) -> np.ndarray:
    """(K,) int64 byte index of the single bit of ``z`` (garbage where z == 0)."""
    return np.frexp(z.view(np.int64).astype(np.float64))[1] // 8 - 1


def _signed_digits(buf, starts, ends):
    """Sign and unsigned length of each token: ``negative (K,) bool, length (K,) int64``."""
    first = buf[starts]
    signed = (first == _MINUS) | (first == _PLUS)
    return first == _MINUS, ends - starts - signed


def _pad_with_zeros(word, garbage):
    """Replace the ``garbage`` (K,) lowest bytes (0..8) of each word by ASCII '0'."""
    keep = _KEEP[garbage]
    return (word & keep) | (_ZEROS & ~keep)


def _fast_decimals(buf, starts, ends, allow_dot):
    """Digits of tokens ``[+-]digits[.digits]`` of at most 16 characters after the sign.

    Returns ``mantissa (K,) uint64`` (the digits as one integer),
    ``fraction_digits (K,) int64`` (digits after the '.'), ``negative (K,) bool``
    and ``ok (K,) bool``; where ``ok`` is False the others are meaningless.
    """
    negative, length = _signed_digits(buf, starts, ends)
    garbage = np.minimum(np.maximum(16 - length, 0), 16)
    all_words = words(buf)
    lo = _pad_with_zeros(all_words[ends - 8], np.maximum(garbage - 8, 0))
    ok = (length >= 1) & (length <= 16)
    wide = bool((length > 8).any())
    hi = _pad_with_zeros(all_words[ends - 16], np.minimum(garbage, 8)) if wide else None
    fraction_digits = np.zeros(len(starts), dtype=np.int64)
    if allow_dot:
        # Close the gap a '.' leaves: the bytes left of it move one byte right
        # (little-endian: one byte up), the freed first byte becomes '0'.
        z_lo = _dot_bytes(lo)
        m_lo = _up_to_dot(z_lo)
        ok &= _single_bit(z_lo) & (length >= 1 + (z_lo != 0))
        fraction_digits = np.where(z_lo != 0, 7 - _dot_byte(z_lo), 0)
        if wide:
            z_hi = _dot_bytes(hi)
            ok &= _single_bit(z_hi) & ((z_hi == 0) | (z_lo == 0))
            m_hi = np.where(z_lo != 0, _ONES, _up_to_dot(z_hi))
            shifted_lo = (lo << _U(8)) | (hi >> _U(56))
            hi = (hi & ~m_hi) | (((hi << _U(8)) | _U(0x30)) & m_hi)
            fraction_digits = np.where(z_hi != 0, 15 - _dot_byte(z_hi), fraction_digits)
        else:
            shifted_lo = (lo << _U(8)) | _U(0x30)
        lo = (lo & ~m_lo) | (shifted_lo & m_lo)
    ok &= _all_digits(lo)
    mantissa = _eight_digits(lo)
    if wide:
        ok &= _all_digits(hi)
        mantissa += _eight_digits(hi) * _U(100000000)
    return mantissa, fraction_digits, negative, ok


def _token_strings(buf, starts, ends) -> np.ndarray:
    """(K,) fixed-width bytes array of the tokens (for the slow fallback)."""
    width = int((ends - starts).max())
    window = np.lib.stride_tricks.sliding_window_view(np.append(buf, np.zeros(width, np.uint8)), width)
    text = window[starts].copy()
    text[np.arange(width) >= (ends - starts)[:, None]] = 0
    return text.view(f"S{width}").ravel()


def parse_floats(buf, starts, ends, finite=False):
    """Parse decimal tokens as float64.

    Returns
    -------
    values : (K,) float64
        NaN/inf only where the token spells them (``nan``, ``inf``, ``1e999``).
    bad : (n,) int64
        Indices of the tokens that are not numbers (``values`` there is NaN),
        and with ``finite`` also of those that are NaN or infinite.
    """
    mantissa, fraction_digits, negative, ok = _fast_decimals(buf, starts, ends, allow_dot=True)
    values = mantissa.view(np.int64).astype(np.float64)  # < 10**16: the sign bit is free
    values /= _SCALE[fraction_digits + 17 * negative]
    slow = np.flatnonzero(~ok)  # only these can be NaN or infinite
    if len(slow) == 0:
        return values, slow
    values[slow], failed = _slow_floats(buf, starts[slow], ends[slow])
    if finite:
        failed |= ~np.isfinite(values[slow])
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

    Returns
    -------
    values : (K,) int64
    bad : (n,) int64
        Indices of the tokens that are not integers (``values`` there is 0).
    """
    mantissa, _, negative, ok = _fast_decimals(buf, starts, ends, allow_dot=False)
    values = mantissa.view(np.int64)
    np.negative(values, out=values, where=negative)
    slow = np.flatnonzero(~ok)
    bad = []
    for k in slow:  # only tokens of more than 16 characters or not integers at all
        try:
            values[k] = int(bytes(buf[starts[k]:ends[k]]))
        except (ValueError, OverflowError):
            bad.append(k)
            values[k] = 0
    return values, np.array(bad, dtype=np.int64)
