"""Numbers as text for whole arrays at once: the ``'%.12g'`` text of every value of a table, byte
for byte what Python's ``%`` writes, built in numpy (the CSV of a long sweep: 10^6 rows of 22
values were 4-5 s of one ``%`` a row).

How: each finite value's 12 significant digits are the integer nearest ``|x| 10^k`` (k = 11 -
its decimal exponent), computed in floating point with at most two roundings (10^k exact for
|k| <= 22), i.e. within 3e-4 of the exact scaled value below 10^12.  Where that error could
change the rounding (the scaled value within 1e-3 of a half), and for infinities, NaN and
|x| outside [1e-33, 1e33), the value is written by Python's ``%`` itself (once per distinct
value); zeros are the digits 000000000000 ("0", "-0").  The digits are then laid out as ``%g`` does: fixed notation for exponents -4
to 11, exponential otherwise, trailing zeros and a bare point dropped.
"""

from __future__ import annotations

import numpy as np

__all__ = ["g12_bytes", "csv_rows"]

P = 12  #: significant digits ("%.12g")
#: bytes a value's text is laid out in (zero bytes where it has no character): sign, "0.000" of the
#: exponents -4..-1, 12 digits with the point among them, "e+123"
W = 1 + 5 + (P + 1) + 5
_POW10 = np.array([float(10 ** i) for i in range(23)])  # exact: every power of ten up to 10^22 is a double
_SMALLEST, _LARGEST = 1e-33, 1e33  # |x| written here: 10^(11 - e) with -33 <= e <= 33 is at most two exact powers
_BAND = 1e-3  # |scaled - (floor + 1/2)| below this: Python's % decides (the float error is below 3e-4)
_FOUR = np.frombuffer("".join(f"{i:04d}" for i in range(10000)).encode(), dtype=np.uint32)  # 4 ASCII digits
_SLOT = np.arange(P + 1, dtype=np.int8)


def _scaled(a: np.ndarray, k: np.ndarray) -> np.ndarray:
    """|x| 10^k for k in [-22, 44] with at most two roundings."""
    p = _POW10[np.minimum(np.abs(k), 22)]
    s = a * p
    down = np.flatnonzero(k < 0)
    s[down] = a[down] / p[down]
    far = np.flatnonzero(k > 22)
    s[far] *= _POW10[k[far] - 22]
    return s


def g12_bytes(values: np.ndarray, out: np.ndarray | None=None) -> np.ndarray:
    """Values (shape S) -> uint8 array (S..., W): the ASCII of ``'%.12g' % value`` of each, with zero
    bytes between and around its characters (drop them when joining); ``out``: an array of zeros of
    that shape (a view) to write into.

    Computed slot by slot (arrays (slots, N): numpy's loops run along the values), selections by
    arithmetic (a boolean times a byte), which is several times faster than np.where on bytes."""
    x = np.asarray(values, dtype=float)
    out = np.zeros(x.shape + (W,), dtype=np.uint8) if out is None else out
    shape, x = x.shape, x.ravel()
    n = len(x)
    a = np.abs(x)
    with np.errstate(all="ignore"):
        fast = np.isfinite(x) & (a >= _SMALLEST) & (a < _LARGEST)
        e = np.floor(np.log10(np.where(fast, a, 1.0))).astype(np.int64)
        s = _scaled(a, P - 1 - e)
        off = np.flatnonzero(fast & ((s >= 10.0 ** P) | (s < 10.0 ** (P - 1))))  # log10 one off near 10^n
        e[off] += np.where(s[off] < 10.0 ** (P - 1), -1, 1)
        s[off] = _scaled(a[off], P - 1 - e[off])
        fast &= (s >= 10.0 ** (P - 1)) & (s < 10.0 ** P)
        fast &= np.abs(s - np.floor(s) - 0.5) >= _BAND
        m = np.where(fast, np.rint(s), 10.0 ** (P - 1))
    carry = m >= 10.0 ** P  # 999999999999.6 -> 10^12: one digit more, the exponent up
    m = np.where(carry, 10.0 ** (P - 1), m)
    e = e + carry
    zero = a == 0  # "0" (or "-0"): the digits 000000000000 with the exponent 0
    m[zero] = 0.0
    fast |= zero
    hi = np.floor(m / 1e8)  # exact: m is an integer below 2^53
    mid = m - hi * 1e8
    lo = np.floor(mid / 1e4)
    groups = np.empty((3, n), dtype=np.int32)
    groups[0], groups[1], groups[2] = hi, lo, mid - lo * 1e4
    digits = np.zeros((P + 1, n), dtype=np.uint8)  # row j: the j-th digit's ASCII (row P: none)
    digits[:P] = _FOUR[groups].view(np.uint8).reshape(3, n, 4).transpose(0, 2, 1).reshape(P, n)
    zeros = np.ones(n, dtype=bool)  # significant digits once trailing zeros are dropped
    nz = np.full(n, P, dtype=np.int8)
    for j in range(P - 1, 0, -1):
        zeros &= digits[j] == ord("0")
        nz -= zeros
    fixed = (e >= -4) & (e < P)
    # the point's slot among the digits (P + 1: none), and the digits written: the integer part, then up to
    # the last nonzero one
    dot = np.where(fixed, np.where(e >= 0, e + 1, P + 1), 1).astype(np.int8)
    limit = np.where(dot <= P, np.maximum(nz, dot), nz)
    slot = _SLOT[:, None]
    after = slot >= dot
    body = digits.copy()  # the digit in each slot is number (slot - after): shifted right after the point
    body[1:] += (digits[:P] - digits[1:]) * after[1:]
    body *= (slot - after) < limit
    point = slot == dot  # the point's slot: "." when a digit follows, else nothing
    body *= ~point
    body += (point & (nz > dot)) * np.uint8(ord("."))
    out[..., 6:6 + P + 1] = body.reshape((P + 1,) + shape).transpose(tuple(range(1, len(shape) + 1)) + (0,))
    out[..., 0] = (np.signbit(x) * np.uint8(ord("-"))).reshape(shape)
    small = fixed & (e < 0)  # 0.000ddd
    if small.any():
        zeros = np.where(small, -e - 1, -1).astype(np.int8)
        for k, (char, written) in enumerate(((ord("0"), small), (ord("."), small), (ord("0"), zeros > 0),
                                             (ord("0"), zeros > 1), (ord("0"), zeros > 2))):
            out[..., 1 + k] = (written * np.uint8(char)).reshape(shape)
    expo = np.flatnonzero(~fixed & fast)
    if len(expo):
        at, ae = np.unravel_index(expo, shape), np.abs(e[expo])
        for k, byte in enumerate((np.full(len(expo), ord("e")), np.where(e[expo] < 0, ord("-"), ord("+")),
                                  np.where(ae >= 100, ae // 100 + ord("0"), 0), (ae // 10) % 10 + ord("0"),
                                  ae % 10 + ord("0"))):
            out[at + (P + 7 + k,)] = byte
    slow = np.flatnonzero(~fast)
    if len(slow):  # Python's % for the rest, once per distinct value (by bits: -0.0 is not 0.0)
        bits, inverse = np.unique(x[slow].view(np.uint64), return_inverse=True)
        text = np.array([("%.12g" % v).encode() for v in bits.view(float).tolist()], dtype=f"S{W}")
        out[np.unravel_index(slow, shape)] = text.view(np.uint8).reshape(-1, W)[inverse.ravel()]
    return out


#: rows formatted at a time: the arrays of a block (44,000 values of 22 columns) stay in the processor's
#: caches, 1.6x faster than 20,000 rows at once; and the byte buffer beside the text stays small
ROWS = 2_000


def csv_rows(columns: list, first: int = 0) -> str:
    """CSV rows ``step,v1,v2,...``: the step numbered from ``first`` (``%d``), then every column
    (equal-length float arrays) as ``'%.12g'``; the same text as ``"%d,%.12g,...\\n" % row`` a row.
    Built ROWS rows at a time, so that the buffers stay small beside the text."""
    cols = [np.asarray(c, dtype=float) for c in columns]
    n = len(cols[0]) if cols else 0
    if n == 0:
        return ""
    if n > ROWS:
        return "".join(csv_rows([c[i:i + ROWS] for c in cols], first + i) for i in range(0, n, ROWS))
    m = len(cols)
    buf = np.zeros((n, m + 1, W + 1), dtype=np.uint8)  # the step, then the values: each W bytes and a separator
    steps = np.arange(first, first + n, dtype=np.int64)
    width = len(str(first + n - 1))
    if width > W:
        raise ValueError(f"step numbers up to {first + n - 1} do not fit {W} characters")
    tens = np.array([10 ** i for i in range(width)], dtype=np.int64)[::-1]
    written = steps[:, None] >= tens  # no leading zeros; the last digit always
    written[:, -1] = True
    buf[:, 0, :width] = np.where(written, (steps[:, None] // tens) % 10 + ord("0"), 0)
    g12_bytes(np.column_stack(cols), out=buf[:, 1:, :W])
    buf[:, :, W] = ord(",")
    buf[:, -1, W] = ord("\n")
    flat = buf.ravel()
    return flat[flat != 0].tobytes().decode("ascii")
