#!/usr/bin/env python3
"""Generate include/mcrt/samplers/sobol_matrices.hpp from Joe and Kuo's table.

The data: the primitive polynomials and initial direction numbers of
S. Joe and F. Y. Kuo, "Constructing Sobol sequences with better
two-dimensional projections", SIAM J. Sci. Comput. 30(5), 2635-2654, 2008,
file "new-joe-kuo-6.21201" (dimensions d = 2..21201), published at
https://web.maths.unsw.edu.au/~fkuo/sobol/ . Its text form is one header line
"d s a m_i" and then one line per dimension:

    d  s  a  m_1 m_2 ... m_s

with s the degree of the primitive polynomial
x^s + a_1 x^(s-1) + ... + a_(s-1) x + 1, a = a_1 ... a_(s-1) read as a binary
number (a_1 its most significant bit), and m_1..m_s the initial direction
integers (m_k odd, m_k < 2^k).

That file is not on the machine this header was generated on. SciPy ships the
same table (scipy/stats/_sobol_direction_numbers.npz, arrays "poly" and
"vinit", 21201 rows: row 0 the van der Corput dimension, row r >= 1 Joe and
Kuo's line d = r + 1) and it was taken from SciPy 1.17.1's wheel, without
installing SciPy:

    python3 -m pip download scipy==1.17.1 --no-deps -d /tmp/scipy_whl
    unzip -j /tmp/scipy_whl/scipy-1.17.1-*.whl \\
        scipy/stats/_sobol_direction_numbers.npz -d /tmp/scipy_whl
    scripts/gen_sobol_matrices.py --npz /tmp/scipy_whl/_sobol_direction_numbers.npz \\
        --write-joe-kuo /tmp/new-joe-kuo-6.21201 \\
        -o include/mcrt/samplers/sobol_matrices.hpp

In the npz, poly holds the whole polynomial as a bit pattern,
poly = 2^s + 2 a + 1, and vinit row r holds m_1..m_s followed by zeros. The
option --npz converts the arrays to Joe and Kuo's text form (the lines above,
which --write-joe-kuo saves) and everything after that reads only the text
form, exactly as --joe-kuo FILE does with the published file; the two routes
give the same header. The .npz is read with the standard library only (a zip
of .npy files; no NumPy needed).

The script checks the first lines against Joe and Kuo's well-known first
lines (d = 2..7) and that every line is well formed (m_k odd, m_k < 2^k,
a < 2^(s-1), the polynomial's constant term 1), then writes the first
`--dims` (default 1024) dimensions: dimension 0 is the van der Corput
sequence (not in the table), dimension k >= 1 is Joe and Kuo's line d = k + 1.
The header computes the 32 direction numbers per dimension itself
(constexpr); this script emits only the compact rows (s, a, m_1..m_s).
"""
from __future__ import annotations

import argparse
import ast
import hashlib
import io
import struct
import sys
import zipfile
from pathlib import Path

# Joe and Kuo's first lines of new-joe-kuo-6.21201: (d, s, a, m_1..m_s).
KNOWN_FIRST_LINES = [
    (2, 1, 0, [1]),
    (3, 2, 1, [1, 3]),
    (4, 3, 1, [1, 3, 1]),
    (5, 3, 2, [1, 1, 1]),
    (6, 4, 1, [1, 1, 3, 3]),
    (7, 4, 4, [1, 3, 5, 13]),
]


def read_npy(data: bytes) -> tuple[str, tuple[int, ...], bool, bytes]:
    """Parse one .npy file (format versions 1-3): dtype descr, shape, order, raw bytes."""
    if data[:6] != b"\x93NUMPY":
        raise ValueError("not a .npy file")
    major = data[6]
    if major == 1:
        (hlen,) = struct.unpack("<H", data[8:10])
        start = 10
    elif major in (2, 3):
        (hlen,) = struct.unpack("<I", data[8:12])
        start = 12
    else:
        raise ValueError(f"unsupported .npy version {major}")
    header = ast.literal_eval(data[start:start + hlen].decode("latin1"))
    return header["descr"], tuple(header["shape"]), bool(header["fortran_order"]), data[start + hlen:]


def npy_int_array(data: bytes) -> tuple[tuple[int, ...], list[int]]:
    descr, shape, fortran, raw = read_npy(data)
    codes = {"<i8": "q", "<i4": "i", "<u8": "Q", "<u4": "I"}
    if descr not in codes:
        raise ValueError(f"unsupported dtype {descr}")
    if len(shape) > 2:
        raise ValueError("arrays of more than 2 dimensions not supported")
    count = 1
    for n in shape:
        count *= n
    values = list(struct.unpack(f"<{count}{codes[descr]}", raw[:count * struct.calcsize(codes[descr])]))
    if fortran and len(shape) == 2:  # column-major on disk: return it row-major
        rows, cols = shape
        values = [values[c * rows + r] for r in range(rows) for c in range(cols)]
    return shape, values


def npz_to_joe_kuo_text(path: Path) -> str:
    """SciPy's npz (poly, vinit) to the text form of new-joe-kuo-6.21201."""
    with zipfile.ZipFile(path) as z:
        pshape, poly = npy_int_array(z.read("poly.npy"))
        vshape, vinit = npy_int_array(z.read("vinit.npy"))
    rows, width = vshape
    if pshape != (rows,):
        raise ValueError(f"poly has shape {pshape}, vinit {vshape}")
    if poly[0] != 1:
        raise ValueError("row 0 of the npz should be the van der Corput dimension (poly = 1)")
    out = io.StringIO()
    out.write("d       s       a       m_i\n")
    for r in range(1, rows):
        p = poly[r]
        s = p.bit_length() - 1
        if s < 1 or p & 1 != 1:
            raise ValueError(f"npz row {r}: poly {p} is not x^s + ... + 1")
        a = (p >> 1) & ((1 << (s - 1)) - 1)
        m = vinit[r * width:r * width + s]
        if any(v != 0 for v in vinit[r * width + s:(r + 1) * width]):
            raise ValueError(f"npz row {r}: nonzero vinit beyond degree {s}")
        out.write(f"{r + 1}       {s}       {a}       " + " ".join(str(v) for v in m) + " \n")
    return out.getvalue()


def parse_joe_kuo(text: str) -> list[tuple[int, int, int, list[int]]]:
    lines = text.splitlines()
    if not lines or lines[0].split()[:3] != ["d", "s", "a"]:
        raise ValueError("expected the header line 'd s a m_i'")
    rows = []
    for n, line in enumerate(lines[1:], start=2):
        f = line.split()
        if not f:
            continue
        d, s, a = int(f[0]), int(f[1]), int(f[2])
        m = [int(v) for v in f[3:]]
        if d != len(rows) + 2:
            raise ValueError(f"line {n}: expected d = {len(rows) + 2}, got {d}")
        if len(m) != s:
            raise ValueError(f"line {n}: d = {d} has s = {s} but {len(m)} m_i")
        if s < 1:
            raise ValueError(f"line {n}: d = {d}: degree s = {s} < 1")
        if not 0 <= a < (1 << (s - 1)):
            raise ValueError(f"line {n}: d = {d}: a = {a} out of range for s = {s}")
        for k, mk in enumerate(m, start=1):
            if mk % 2 != 1 or mk >= (1 << k):
                raise ValueError(f"line {n}: d = {d}: m_{k} = {mk} must be odd and < 2^{k}")
        rows.append((d, s, a, m))
    return rows


def check_known(rows) -> None:
    for expected, got in zip(KNOWN_FIRST_LINES, rows):
        if (expected[0], expected[1], expected[2], expected[3]) != (got[0], got[1], got[2], got[3]):
            raise ValueError(f"line d = {expected[0]}: expected {expected}, got {got}")


def emit_header(rows, dims: int, source: str) -> str:
    used = rows[:dims - 1]
    max_s = max(s for _, s, _, _ in used)
    body = []
    for d, s, a, m in used:
        body.append(f"    {{{s}, {a}, {{{', '.join(str(v) for v in m)}}}}},  // d = {d}")
    rows_text = "\n".join(body)
    return HEADER_TEMPLATE.format(dims=dims, max_s=max_s, rows=rows_text, count=len(used), source=source,
                                  last_d=used[-1][0])


HEADER_TEMPLATE = """\
#pragma once
// Generator matrices of Sobol's sequence (I. M. Sobol', "On the distribution
// of points in a cube and the approximate evaluation of integrals", USSR
// Comput. Math. Math. Phys. 7(4), 1967) for the first {dims} dimensions, from
// the direction numbers of S. Joe and F. Y. Kuo, "Constructing Sobol
// sequences with better two-dimensional projections", SIAM J. Sci. Comput.
// 30(5), 2008, table "new-joe-kuo-6.21201".
//
// GENERATED by scripts/gen_sobol_matrices.py; do not edit the rows by hand.
// Source of the rows: {source}
// (see the script's docstring for how the table was obtained and checked).
//
// Dimension 0 is the van der Corput sequence (identity generator matrix, not
// in the table); dimension k >= 1 is Joe and Kuo's line d = k + 1, stored as
// the compact row (s, a, m_1..m_s): the primitive polynomial
// x^s + a_1 x^(s-1) + ... + a_(s-1) x + 1 of degree s, a = a_1...a_(s-1) in
// binary (a_1 the most significant bit), and the initial direction integers
// m_k (odd, m_k < 2^k).
//
// Direction numbers, 32-bit fixed point: v_k = m_k 2^(32-k), k = 1..32, the
// k-th column of the generator matrix (the point of index i is the XOR of v_k
// over the set bits k-1 of i, samplers/sobol.hpp). The first s come from the
// table; the others from the recurrence of Bratley and Fox 1988 ("Algorithm
// 659: Implementing Sobol's quasirandom sequence generator", ACM TOMS 14(1)),
// as Joe and Kuo's "Notes on generating Sobol' sequences" (2008) state it:
//   m_k = 2 a_1 m_(k-1) ^ 2^2 a_2 m_(k-2) ^ ... ^ 2^(s-1) a_(s-1) m_(k-s+1)
//         ^ 2^s m_(k-s) ^ m_(k-s),                                     k > s,
// which on v_k = m_k 2^(32-k) reads
//   v_k = v_(k-s) ^ (v_(k-s) >> s) ^ XOR_(j=1..s-1) a_j v_(k-j).
// sobol_direction_numbers(dim) is constexpr (one dimension costs nothing to
// evaluate at compile time); the whole 32 x {dims} table, sobol_matrices(), is
// computed once, on first use, into a function-local static (thread-safe
// initialisation since C++11): evaluating all of it as a constexpr variable
// would add ~1 s to the compilation of every file that includes this header.
#include <array>
#include <cstdint>

namespace mcrt {{

inline constexpr int sobol_dimensions = {dims};  // dimensions 0 .. sobol_dimensions - 1
inline constexpr int sobol_bits = 32;          // direction numbers per dimension
inline constexpr int sobol_max_degree = {max_s};    // the largest s among the rows below

// One line of Joe and Kuo's table.
struct sobol_polynomial {{
  std::uint8_t s;                            // degree
  std::uint16_t a;                           // inner coefficients a_1..a_(s-1), a_1 the top bit
  std::uint16_t m[sobol_max_degree];         // m_1..m_s, then zeros
}};

// sobol_rows[k - 1] describes dimension k (Joe and Kuo's d = k + 1), k = 1..{count}.
inline constexpr sobol_polynomial sobol_rows[sobol_dimensions - 1] = {{
{rows}
}};

// The 32 direction numbers v_1..v_32 (index 0..31) of dimension dim.
constexpr std::array<std::uint32_t, sobol_bits> sobol_direction_numbers(int dim) {{
  std::array<std::uint32_t, sobol_bits> v{{}};
  if (dim == 0) {{  // van der Corput: m_k = 1 for every k
    for (int k = 0; k < sobol_bits; ++k) v[k] = 1u << (sobol_bits - 1 - k);
    return v;
  }}
  const sobol_polynomial& p = sobol_rows[dim - 1];
  const int s = p.s;
  for (int k = 0; k < s; ++k) v[k] = static_cast<std::uint32_t>(p.m[k]) << (sobol_bits - 1 - k);
  for (int k = s; k < sobol_bits; ++k) {{
    std::uint32_t x = v[k - s] ^ (v[k - s] >> s);
    for (int j = 1; j < s; ++j)
      if ((p.a >> (s - 1 - j)) & 1u) x ^= v[k - j];
    v[k] = x;
  }}
  return v;
}}

using sobol_matrix_table = std::array<std::array<std::uint32_t, sobol_bits>, sobol_dimensions>;

// Not constexpr on purpose: a constant initialiser would make the compiler
// evaluate the whole table for the static below in every translation unit.
inline sobol_matrix_table make_sobol_matrices() {{
  sobol_matrix_table t{{}};
  for (int d = 0; d < sobol_dimensions; ++d) t[d] = sobol_direction_numbers(d);
  return t;
}}

// sobol_matrices()[dim][k] = v_(k+1) of dimension dim; computed on the first
// call (about 0.1 ms), thread-safe.
inline const sobol_matrix_table& sobol_matrices() {{
  static const sobol_matrix_table table = make_sobol_matrices();
  return table;
}}

}}  // namespace mcrt
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--joe-kuo", type=Path, help="Joe and Kuo's text table (new-joe-kuo-6.21201)")
    src.add_argument("--npz", type=Path, help="SciPy's scipy/stats/_sobol_direction_numbers.npz")
    ap.add_argument("--write-joe-kuo", type=Path, help="with --npz: also save the converted text table here")
    ap.add_argument("--dims", type=int, default=1024, help="dimensions to emit (default 1024)")
    ap.add_argument("-o", "--output", type=Path, required=True, help="header to write")
    args = ap.parse_args()

    raw_path = args.joe_kuo or args.npz
    digest = hashlib.sha256(raw_path.read_bytes()).hexdigest()
    if args.npz:
        text = npz_to_joe_kuo_text(args.npz)
        if args.write_joe_kuo:
            args.write_joe_kuo.write_text(text)
        source = (f"scipy/stats/_sobol_direction_numbers.npz of SciPy's wheel\n// (sha256 {digest}),\n"
                  "// converted to Joe and Kuo's text form by the script (--npz)")
    else:
        text = args.joe_kuo.read_text()
        source = f"{args.joe_kuo.name} (sha256 {digest})"
    rows = parse_joe_kuo(text)
    check_known(rows)
    if not 2 <= args.dims <= len(rows) + 1:
        raise ValueError(f"--dims must be in [2, {len(rows) + 1}]")
    args.output.write_text(emit_header(rows, args.dims, source))
    print(f"{args.output}: {args.dims} dimensions from {len(rows)} table lines "
          f"(d = 2..{rows[-1][0]}), source sha256 {digest}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
