//! Exact geometric predicates with a floating-point filter in front.
//!
//! Every predicate returns the exact sign of its determinant for any finite
//! `f64` input (barring overflow or underflow of the intermediate products,
//! i.e. coordinates beyond about 1e±60). The fast path evaluates the
//! determinant in plain `f64` together with Shewchuk's static error bound
//! computed from the permanent; only when the result is within that bound
//! do we fall back to the adaptive-precision arithmetic of the `robust`
//! crate, which is exact.
//!
//! Sign conventions follow CGAL:
//!
//! * [`orient3d`]`(a, b, c, d)` is the sign of `det[b − a, c − a, d − a]`:
//!   positive when `d` lies on the side of plane `abc` from which `a, b, c`
//!   appear clockwise... equivalently when `(a, b, c, d)` is a positively
//!   oriented (right-handed) tetrahedron.
//! * [`insphere`]`(a, b, c, d, e)` is positive when `e` lies strictly inside
//!   the circumsphere of the *positively oriented* tetrahedron `abcd`.

use super::wide::{insphere_narrow_f, insphere_wide, orient3d_narrow_f, orient3d_wide};
use robust::{Coord, Coord3D};

/// A point in 3D.
pub type Point3 = [f64; 3];

/// The sign of a predicate's determinant, which every exact predicate of
/// this module returns. Ordered `Negative < Zero < Positive`.
///
/// ```
/// use aniso_alpha::geometry::Sign;
/// assert_eq!(Sign::of(-0.5), Sign::Negative);
/// assert_eq!(-Sign::Negative * Sign::Positive, Sign::Positive);
/// assert!(Sign::Zero >= Sign::Negative);
/// assert_eq!(Sign::Positive.to_i32(), 1);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(i8)]
pub enum Sign {
    /// Negative.
    Negative = -1,
    /// Zero: the points are degenerate for this predicate (coplanar,
    /// cospherical, on the circle, ...).
    Zero = 0,
    /// Positive.
    Positive = 1,
}

impl Sign {
    /// The sign of `x` (`Zero` for `±0`; `x` must not be NaN).
    #[inline]
    pub fn of(x: f64) -> Sign {
        if x > 0.0 {
            Sign::Positive
        } else if x < 0.0 {
            Sign::Negative
        } else {
            Sign::Zero
        }
    }

    /// The sign of the integer `s`.
    #[inline]
    pub const fn of_i32(s: i32) -> Sign {
        if s > 0 {
            Sign::Positive
        } else if s < 0 {
            Sign::Negative
        } else {
            Sign::Zero
        }
    }

    /// `1`, `0` or `-1`.
    #[inline]
    pub const fn to_i32(self) -> i32 {
        self as i32
    }

    /// Whether the sign is [`Sign::Positive`].
    #[inline]
    pub const fn is_positive(self) -> bool {
        matches!(self, Sign::Positive)
    }

    /// Whether the sign is [`Sign::Negative`].
    #[inline]
    pub const fn is_negative(self) -> bool {
        matches!(self, Sign::Negative)
    }

    /// Whether the sign is [`Sign::Zero`].
    #[inline]
    pub const fn is_zero(self) -> bool {
        matches!(self, Sign::Zero)
    }
}

impl std::ops::Neg for Sign {
    type Output = Sign;
    #[inline]
    fn neg(self) -> Sign {
        Sign::of_i32(-self.to_i32())
    }
}

impl std::ops::Mul for Sign {
    type Output = Sign;
    #[inline]
    fn mul(self, other: Sign) -> Sign {
        Sign::of_i32(self.to_i32() * other.to_i32())
    }
}

impl From<Sign> for i32 {
    fn from(s: Sign) -> i32 {
        s.to_i32()
    }
}

/// Exact difference `a − b` if it is representable, else `None`
/// (Knuth's two-diff: the rounding error of the subtraction is zero).
#[inline(always)]
fn exact_diff(a: f64, b: f64) -> Option<f64> {
    let x = a - b;
    let bvirt = a - x;
    let avirt = x + bvirt;
    let bround = bvirt - b;
    let around = a - avirt;
    if around + bround == 0.0 {
        Some(x)
    } else {
        None
    }
}

/// Maximum bit width of the scaled integers of the integer stage: with
/// |d| < 2^23 the in-sphere determinant stays below 2^122 in `i128`.
const INT_BITS: i32 = 23;

/// Writes `d` as integers `k_i` with `d_i = k_i · 2^L` for a common `L`, if
/// every `d_i` is finite, normal (or zero) and they all fit in
/// [`INT_BITS`] bits after scaling. This is the case for grid-like data
/// (integer or dyadic coordinates), which is where exact ties happen.
#[inline]
fn scaled_ints<const N: usize>(d: &[f64; N]) -> Option<[i64; N]> {
    let mut lo = i32::MAX;
    let mut hi = i32::MIN;
    for &x in d {
        if x == 0.0 {
            continue;
        }
        let bits = x.to_bits();
        let exp = ((bits >> 52) & 0x7ff) as i32;
        if exp == 0 || exp == 0x7ff {
            return None;
        }
        let mant = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
        let low = exp - 1075 + mant.trailing_zeros() as i32;
        let high = exp - 1075 + 53;
        lo = lo.min(low);
        hi = hi.max(high);
    }
    if lo == i32::MAX {
        return Some([0; N]);
    }
    if hi - lo > INT_BITS {
        return None;
    }
    let mut out = [0i64; N];
    for (o, &x) in out.iter_mut().zip(d) {
        if x == 0.0 {
            continue;
        }
        let bits = x.to_bits();
        let exp = ((bits >> 52) & 0x7ff) as i32;
        let mant = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
        let shift = exp - 1075 - lo; // value = mant · 2^(exp−1075) = k · 2^lo
        let k = if shift >= 0 {
            (mant << shift) as i64
        } else {
            (mant >> (-shift)) as i64
        };
        *o = if x < 0.0 { -k } else { k };
    }
    Some(out)
}

/// Exact sign of `det[a − d, b − d, c − d]` (Shewchuk's orient3d) by the
/// integer stage, when it applies.
fn orient3d_int(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> Option<i32> {
    let mut diffs = [0.0; 9];
    for k in 0..3 {
        diffs[k] = exact_diff(a[k], d[k])?;
        diffs[3 + k] = exact_diff(b[k], d[k])?;
        diffs[6 + k] = exact_diff(c[k], d[k])?;
    }
    let q = scaled_ints(&diffs)?;
    let m = |i: usize, j: usize, k: usize, l: usize| (q[i] * q[j] - q[k] * q[l]) as i128;
    // rows a, b, c; columns x, y, z
    let det =
        q[2] as i128 * m(3, 7, 6, 4) + q[5] as i128 * m(6, 1, 0, 7) + q[8] as i128 * m(0, 4, 3, 1);
    Some(det.signum() as i32)
}

/// Exact sign of Shewchuk's insphere determinant by the integer stage,
/// when it applies.
fn insphere_int(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> Option<i32> {
    let mut diffs = [0.0; 12];
    for (r, p) in [a, b, c, d].iter().enumerate() {
        for k in 0..3 {
            diffs[3 * r + k] = exact_diff(p[k], e[k])?;
        }
    }
    let q = scaled_ints(&diffs)?;
    let x = |r: usize| q[3 * r];
    let y = |r: usize| q[3 * r + 1];
    let z = |r: usize| q[3 * r + 2];
    let lift = |r: usize| (x(r) * x(r) + y(r) * y(r) + z(r) * z(r)) as i128;
    // 2x2 minors in (x, y).
    let xy = |r: usize, s: usize| (x(r) * y(s) - x(s) * y(r)) as i128;
    let ab = xy(0, 1);
    let bc = xy(1, 2);
    let cd = xy(2, 3);
    let da = xy(3, 0);
    let ac = xy(0, 2);
    let bd = xy(1, 3);
    let zi = |r: usize| z(r) as i128;
    let abc = zi(0) * bc - zi(1) * ac + zi(2) * ab;
    let bcd = zi(1) * cd - zi(2) * bd + zi(3) * bc;
    let cda = zi(2) * da + zi(3) * ac + zi(0) * cd;
    let dab = zi(3) * ab + zi(0) * bd + zi(1) * da;
    let det = (lift(3) * abc - lift(2) * dab) + (lift(1) * cda - lift(0) * bcd);
    Some(det.signum() as i32)
}

/// `max` for non-NaN inputs, compiled to a single instruction (unlike
/// `f64::max`, which must handle NaN).
#[inline(always)]
fn fmax(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

#[inline(always)]
fn c3(p: &Point3) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

#[inline(always)]
fn sign(x: f64) -> i32 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// The differences `a − d, b − d, c − d`, flattened by point.
#[inline(always)]
fn diffs3(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> [f64; 9] {
    [
        a[0] - d[0],
        a[1] - d[1],
        a[2] - d[2],
        b[0] - d[0],
        b[1] - d[1],
        b[2] - d[2],
        c[0] - d[0],
        c[1] - d[1],
        c[2] - d[2],
    ]
}

/// The differences `a − e, b − e, c − e, d − e`, flattened by point.
#[inline(always)]
fn diffs4(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> [f64; 12] {
    [
        a[0] - e[0],
        a[1] - e[1],
        a[2] - e[2],
        b[0] - e[0],
        b[1] - e[1],
        b[2] - e[2],
        c[0] - e[0],
        c[1] - e[1],
        c[2] - e[2],
        d[0] - e[0],
        d[1] - e[1],
        d[2] - e[2],
    ]
}

/// Shewchuk's orient3d determinant `det[a − d, b − d, c − d]` in plain f64
/// from the differences: the same operations as the filtered fast path of
/// [`orient3d`], which keeps its own straight-line copy (calling this
/// helper there measured 2–3% more instructions per insertion).
#[inline(always)]
fn orient_det(d: &[f64; 9]) -> f64 {
    let [adx, ady, adz, bdx, bdy, bdz, cdx, cdy, cdz] = *d;
    adz * (bdx * cdy - cdx * bdy) + bdz * (cdx * ady - adx * cdy) + cdz * (adx * bdy - bdx * ady)
}

/// Shewchuk's insphere determinant in plain f64 from the differences
/// `a − e, b − e, c − e, d − e`: the same operations as the filtered fast
/// path of [`insphere`], which keeps its own straight-line copy for speed
/// (see [`orient_det`]).
#[inline(always)]
fn insphere_det(d: &[f64; 12]) -> f64 {
    let [aex, aey, aez, bex, bey, bez, cex, cey, cez, dex, dey, dez] = *d;
    let ab = aex * bey - bex * aey;
    let bc = bex * cey - cex * bey;
    let cd = cex * dey - dex * cey;
    let da = dex * aey - aex * dey;
    let ac = aex * cey - cex * aey;
    let bd = bex * dey - dex * bey;
    let abc = aez * bc - bez * ac + cez * ab;
    let bcd = bez * cd - cez * bd + dez * bc;
    let cda = cez * da + dez * ac + aez * cd;
    let dab = dez * ab + aez * bd + bez * da;
    let alift = aex * aex + aey * aey + aez * aez;
    let blift = bex * bex + bey * bey + bez * bez;
    let clift = cex * cex + cey * cey + cez * cez;
    let dlift = dex * dex + dey * dey + dez * dez;
    (dlift * abc - clift * dab) + (blift * cda - alift * bcd)
}

/// Exact sign of `det[b − a, c − a, d − a]`: `1` if `(a, b, c, d)` is
/// positively oriented, `-1` if negatively, `0` if the four points are
/// coplanar.
///
/// ```
/// use aniso_alpha::geometry::predicates::{orient3d, Sign};
/// let o = [0.0, 0.0, 0.0];
/// assert_eq!(orient3d(&o, &[1.0, 0.0, 0.0], &[0.0, 1.0, 0.0], &[0.0, 0.0, 1.0]), Sign::Positive);
/// assert_eq!(orient3d(&o, &[0.0, 1.0, 0.0], &[1.0, 0.0, 0.0], &[0.0, 0.0, 1.0]), Sign::Negative);
/// assert_eq!(orient3d(&o, &[1.0, 0.0, 0.0], &[0.0, 1.0, 0.0], &[1.0, 1.0, 0.0]), Sign::Zero);
/// ```
#[inline(always)]
pub fn orient3d(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> Sign {
    Sign::of_i32(orient3d_with(a, b, c, d, f64::INFINITY))
}

/// [`orient3d`], first trying a static bound on the error of the plain
/// determinant (see [`StaticFilter`]; `+∞` skips that step).
#[inline(always)]
fn orient3d_with(a: &Point3, b: &Point3, c: &Point3, d: &Point3, static_bound: f64) -> i32 {
    orient3d_stages::<true>(a, b, c, d, static_bound)
}

/// Only the static stage of [`orient3d_with`]: its sign, or `0` if the
/// static bound does not settle it.
#[inline(always)]
fn orient3d_static_stage(a: &Point3, b: &Point3, c: &Point3, d: &Point3, static_bound: f64) -> i32 {
    orient3d_stages::<false>(a, b, c, d, static_bound)
}

/// [`orient3d_with`] (`FULL`) or its static stage alone.
#[inline(always)]
fn orient3d_stages<const FULL: bool>(
    a: &Point3,
    b: &Point3,
    c: &Point3,
    d: &Point3,
    static_bound: f64,
) -> i32 {
    // Shewchuk's orient3d(a, b, c, d) = det[a − d, b − d, c − d] = −det[b − a, c − a, d − a].
    let adx = a[0] - d[0];
    let bdx = b[0] - d[0];
    let cdx = c[0] - d[0];
    let ady = a[1] - d[1];
    let bdy = b[1] - d[1];
    let cdy = c[1] - d[1];
    let adz = a[2] - d[2];
    let bdz = b[2] - d[2];
    let cdz = c[2] - d[2];

    let det = adz * (bdx * cdy - cdx * bdy)
        + bdz * (cdx * ady - adx * cdy)
        + cdz * (adx * bdy - bdx * ady);
    if det > static_bound {
        return -1;
    }
    if -det > static_bound {
        return 1;
    }
    if !FULL {
        return 0;
    }
    // Semi-static filter: Shewchuk's bound is O3D_ERRBOUND_A times the
    // permanent, and the permanent is at most 6·X·Y·Z where X, Y, Z bound
    // the absolute differences per axis. 4.7e-15 > 6·(7 + 56ε)ε with margin
    // for the rounding of the product itself.
    let mx = fmax(fmax(adx.abs(), bdx.abs()), cdx.abs());
    let my = fmax(fmax(ady.abs(), bdy.abs()), cdy.abs());
    let mz = fmax(fmax(adz.abs(), bdz.abs()), cdz.abs());
    let eps = 4.7e-15 * (mx * my * mz);
    if (det > eps || -det > eps) && eps < f64::MAX && eps > f64::MIN_POSITIVE {
        return -sign(det);
    }
    orient3d_slow(a, b, c, d)
}

/// Exact in-sphere test: `1` if `e` is strictly inside the circumsphere of
/// the positively oriented tetrahedron `(a, b, c, d)`, `-1` if strictly
/// outside, `0` if the five points are cospherical. If `(a, b, c, d)` is
/// negatively oriented the sign is reversed.
///
/// ```
/// use aniso_alpha::geometry::predicates::{insphere, Sign};
/// let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// assert_eq!(insphere(&t[0], &t[1], &t[2], &t[3], &[0.2, 0.2, 0.2]), Sign::Positive);
/// assert_eq!(insphere(&t[0], &t[1], &t[2], &t[3], &[1.0, 1.0, 1.0]), Sign::Zero);
/// assert_eq!(insphere(&t[0], &t[1], &t[2], &t[3], &[2.0, 2.0, 2.0]), Sign::Negative);
/// ```
#[inline(always)]
pub fn insphere(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> Sign {
    Sign::of_i32(insphere_with(a, b, c, d, e, f64::INFINITY))
}

/// [`insphere`], first trying a static bound on the error of the plain
/// determinant (see [`StaticFilter`]; `+∞` skips that step).
#[inline(always)]
fn insphere_with(
    a: &Point3,
    b: &Point3,
    c: &Point3,
    d: &Point3,
    e: &Point3,
    static_bound: f64,
) -> i32 {
    insphere_stages::<true>(a, b, c, d, e, static_bound)
}

/// Only the static stage of [`insphere_with`]: its sign, or `0` if the
/// static bound does not settle it.
#[inline(always)]
fn insphere_static_stage(
    a: &Point3,
    b: &Point3,
    c: &Point3,
    d: &Point3,
    e: &Point3,
    static_bound: f64,
) -> i32 {
    insphere_stages::<false>(a, b, c, d, e, static_bound)
}

/// [`insphere_with`] (`FULL`) or its static stage alone.
#[inline(always)]
fn insphere_stages<const FULL: bool>(
    a: &Point3,
    b: &Point3,
    c: &Point3,
    d: &Point3,
    e: &Point3,
    static_bound: f64,
) -> i32 {
    let aex = a[0] - e[0];
    let bex = b[0] - e[0];
    let cex = c[0] - e[0];
    let dex = d[0] - e[0];
    let aey = a[1] - e[1];
    let bey = b[1] - e[1];
    let cey = c[1] - e[1];
    let dey = d[1] - e[1];
    let aez = a[2] - e[2];
    let bez = b[2] - e[2];
    let cez = c[2] - e[2];
    let dez = d[2] - e[2];

    let ab = aex * bey - bex * aey;
    let bc = bex * cey - cex * bey;
    let cd = cex * dey - dex * cey;
    let da = dex * aey - aex * dey;
    let ac = aex * cey - cex * aey;
    let bd = bex * dey - dex * bey;

    let abc = aez * bc - bez * ac + cez * ab;
    let bcd = bez * cd - cez * bd + dez * bc;
    let cda = cez * da + dez * ac + aez * cd;
    let dab = dez * ab + aez * bd + bez * da;

    let alift = aex * aex + aey * aey + aez * aez;
    let blift = bex * bex + bey * bey + bez * bez;
    let clift = cex * cex + cey * cey + cez * cez;
    let dlift = dex * dex + dey * dey + dez * dez;

    let det = (dlift * abc - clift * dab) + (blift * cda - alift * bcd);
    // Shewchuk's insphere is positive for "inside" when (a, b, c, d) has *his*
    // positive orientation, which is CGAL's negative one: negate.
    if det > static_bound {
        return -1;
    }
    if -det > static_bound {
        return 1;
    }
    if !FULL {
        return 0;
    }

    // Semi-static filter: Shewchuk's bound is ISP_ERRBOUND_A times the
    // permanent, and the permanent is at most 72·M²·X·Y·Z where X, Y, Z
    // bound the absolute differences per axis and M = max(X, Y, Z) (each
    // lift is at most 3M², each 3x3 permanent at most 6XYZ). 1.28e-13 >
    // 72·(16 + 224ε)ε = 1.27898e-13, with margin for rounding.
    let mx = fmax(fmax(aex.abs(), bex.abs()), fmax(cex.abs(), dex.abs()));
    let my = fmax(fmax(aey.abs(), bey.abs()), fmax(cey.abs(), dey.abs()));
    let mz = fmax(fmax(aez.abs(), bez.abs()), fmax(cez.abs(), dez.abs()));
    let m = fmax(fmax(mx, my), mz);
    let eps = 1.28e-13 * (mx * my * mz) * (m * m);
    if (det > eps || -det > eps) && eps < f64::MAX && eps > f64::MIN_POSITIVE {
        return -sign(det);
    }
    insphere_slow(a, b, c, d, e)
}

/// Whether every value is an integer of magnitude below `limit`. For
/// integer inputs below 2^52 the differences are exact, and a determinant
/// of small integer differences whose every intermediate stays below 2^53
/// is computed exactly by plain `f64` arithmetic.
#[inline(always)]
fn small_ints(d: &[f64], limit: f64) -> bool {
    d.iter().all(|&x| x.abs() < limit && x == (x as i64) as f64)
}

#[cold]
#[inline(never)]
fn orient3d_slow(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> i32 {
    // Integer differences below 2^16: |det| < 6·2^48 and every product and
    // sum of the evaluation is an exact f64. The inputs must be integers
    // themselves (then, below 2^52, their differences are exact); checking
    // only the rounded differences would accept 3 − 1e−20 as the integer 3.
    let r = diffs3(a, b, c, d);
    if small_ints(&r, 65536.0) && [a, b, c, d].iter().all(|p| small_ints(&p[..], 4.5e15)) {
        return -sign(orient_det(&r));
    }
    // Then exact integers: coordinates within 60 bits of each other (most
    // data), differences within 23 bits (coordinates far from the origin),
    // coordinates within 100 bits, and only beyond that `robust`'s
    // expansions.
    if let Some(s) = orient3d_narrow_f(a, b, c, d) {
        return -s;
    }
    if let Some(s) = orient3d_int(a, b, c, d) {
        return -s;
    }
    if let Some(s) = orient3d_wide(a, b, c, d) {
        return -s;
    }
    -sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
}

#[cold]
#[inline(never)]
fn insphere_slow(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> i32 {
    // Integer differences below 2^9: lifts < 3·2^18, 2x2 minors < 2^19,
    // 3x3 minors < 3·2^28, |det| < 4·3·2^18·3·2^28 < 2^53: plain f64 is
    // exact (and subtracting integers below 2^53 is exact too).
    let r = diffs4(a, b, c, d, e);
    if small_ints(&r, 512.0) && [a, b, c, d, e].iter().all(|p| small_ints(&p[..], 4.5e15)) {
        return -sign(insphere_det(&r));
    }
    // Then exact integers, as in `orient3d_slow`.
    if let Some(s) = insphere_narrow_f(a, b, c, d, e) {
        return -s;
    }
    if let Some(s) = insphere_int(a, b, c, d, e) {
        return -s;
    }
    if let Some(s) = insphere_wide(a, b, c, d, e) {
        return -s;
    }
    -sign(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)))
}

/// A choice of implementation for the two hot predicates. Both kernels
/// return exact signs; [`SmallGrid`] is only valid for inputs that
/// [`SmallGrid::applies`] accepts.
pub(crate) trait Kernel: Copy + Send + Sync {
    /// Exact sign of `det[b − a, c − a, d − a]`, as [`orient3d`].
    fn orient3d(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> i32;
    /// Exact in-sphere sign, as [`insphere`].
    fn insphere(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> i32;
    /// [`Kernel::orient3d`] for points of the set `filter` was made for,
    /// trying its static bound first.
    #[inline(always)]
    fn orient3d_static(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        filter: &StaticFilter,
    ) -> i32 {
        let _ = filter;
        Self::orient3d(a, b, c, d)
    }
    /// [`Kernel::insphere`] for points of the set `filter` was made for,
    /// trying its static bound first.
    #[inline(always)]
    fn insphere_static(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        e: &Point3,
        filter: &StaticFilter,
    ) -> i32 {
        let _ = filter;
        Self::insphere(a, b, c, d, e)
    }
    /// The sign of [`Kernel::orient3d_static`] when the kernel's cheap
    /// first stage settles it (the static bound), else `0`: `0` does not
    /// mean the points are coplanar.
    #[inline(always)]
    fn orient3d_quick(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        filter: &StaticFilter,
    ) -> i32 {
        let _ = (a, b, c, d, filter);
        0
    }
    /// Whether the quick stages are exact, so that their `0` is a tie
    /// (only for the inputs the kernel is valid for).
    const QUICK_IS_EXACT: bool = false;
    /// The sign of [`Kernel::insphere_static`] when the kernel's cheap
    /// first stage settles it, else `0` (not necessarily a tie).
    #[inline(always)]
    fn insphere_quick(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        e: &Point3,
        filter: &StaticFilter,
    ) -> i32 {
        let _ = (a, b, c, d, e, filter);
        0
    }
}

/// Static error bounds for the two determinants, valid for every tuple of
/// points from one set: the semi-static bounds of [`orient3d`] and
/// [`insphere`] evaluated with the extents of the set's bounding box, which
/// bound every coordinate difference (rounding is monotone, so a rounded
/// difference never exceeds the rounded extent). A determinant beyond its
/// static bound has a certain sign with a single comparison, skipping the
/// per-call bound; anything else goes through the full filtered predicate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StaticFilter {
    orient: f64,
    insphere: f64,
}

impl StaticFilter {
    /// A filter that never decides, so every call takes the full path.
    #[cfg(test)]
    pub(crate) const NONE: StaticFilter = StaticFilter {
        orient: f64::INFINITY,
        insphere: f64::INFINITY,
    };

    /// The static bounds for points inside the box `[lo, hi]`.
    ///
    /// A bound is only used when it lies in `[1e-200, 1e300]`: there the
    /// determinant's products can neither overflow nor underflow enough to
    /// matter (a computed determinant whose true magnitude bound is below
    /// the smallest normal number is itself far below 1e-200, so it never
    /// passes), which is what the semi-static filter checks per call.
    pub(crate) fn for_box(lo: &Point3, hi: &Point3) -> StaticFilter {
        let x = hi[0] - lo[0];
        let y = hi[1] - lo[1];
        let z = hi[2] - lo[2];
        let m = fmax(fmax(x, y), z);
        let usable = |b: f64| {
            if (1e-200..=1e300).contains(&b) {
                b
            } else {
                f64::INFINITY
            }
        };
        StaticFilter {
            orient: usable(4.7e-15 * (x * y * z)),
            insphere: usable(1.28e-13 * (x * y * z) * (m * m)),
        }
    }

    /// The static bounds for a set of finite points.
    #[cfg(test)]
    pub(crate) fn for_points(points: &[Point3]) -> StaticFilter {
        let (lo, hi) = super::bounding_box(points);
        if points.is_empty() || !lo.iter().chain(&hi).all(|v| v.is_finite()) {
            return StaticFilter::NONE;
        }
        StaticFilter::for_box(&lo, &hi)
    }
}

/// The general kernel: floating-point filter, then exact stages.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Filtered;

impl Kernel for Filtered {
    #[inline(always)]
    fn orient3d(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> i32 {
        orient3d_with(a, b, c, d, f64::INFINITY)
    }
    #[inline(always)]
    fn insphere(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> i32 {
        insphere_with(a, b, c, d, e, f64::INFINITY)
    }
    #[inline(always)]
    fn orient3d_static(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        filter: &StaticFilter,
    ) -> i32 {
        orient3d_with(a, b, c, d, filter.orient)
    }
    #[inline(always)]
    fn insphere_static(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        e: &Point3,
        filter: &StaticFilter,
    ) -> i32 {
        insphere_with(a, b, c, d, e, filter.insphere)
    }
    #[inline(always)]
    fn orient3d_quick(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        filter: &StaticFilter,
    ) -> i32 {
        orient3d_static_stage(a, b, c, d, filter.orient)
    }
    #[inline(always)]
    fn insphere_quick(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        e: &Point3,
        filter: &StaticFilter,
    ) -> i32 {
        insphere_static_stage(a, b, c, d, e, filter.insphere)
    }
}

/// A kernel for points on a small dyadic grid (e.g. integer grids up to
/// 512 wide): every coordinate is `k · 2^L` for one `L`, with the extent of
/// the set below `2^9 · 2^L` on every axis. Then every difference is an
/// integer multiple of `2^L` below `2^9` steps and plain `f64` evaluation of
/// both determinants is exact (|insphere| < 2^53 steps, see
/// `insphere_slow`), so no filter is needed. Degenerate grids are exactly
/// where the filtered kernel is slowest (most tests are exact ties).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SmallGrid;

impl SmallGrid {
    /// Whether the points satisfy the condition of [`SmallGrid`].
    #[cfg(test)]
    pub(crate) fn applies(points: &[Point3]) -> bool {
        Self::frame(points).is_some()
    }

    /// The grid of a set [`SmallGrid::applies`] to: the lowest coordinate
    /// per axis and the step `2^L` (1 for a set of zeros), else `None`.
    pub(crate) fn frame(points: &[Point3]) -> Option<([f64; 3], f64)> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut low_bit = i32::MAX;
        for chunk in points.chunks(256) {
            for p in chunk {
                for k in 0..3 {
                    let x = p[k];
                    if !x.is_finite() {
                        return None;
                    }
                    lo[k] = lo[k].min(x);
                    hi[k] = hi[k].max(x);
                    if x != 0.0 {
                        let bits = x.to_bits();
                        let exp = ((bits >> 52) & 0x7ff) as i32;
                        if exp == 0 {
                            return None; // subnormal
                        }
                        let mant = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
                        low_bit = low_bit.min(exp - 1075 + mant.trailing_zeros() as i32);
                    }
                }
            }
            // The step only shrinks and the extent only grows: a set that
            // is already 512 steps wide never becomes a small grid (most
            // float inputs stop here after their first chunk).
            if low_bit != i32::MAX {
                let step = 2f64.powi(low_bit);
                if !(0..3).all(|k| (hi[k] - lo[k]) / step < 512.0) {
                    return None;
                }
            }
        }
        if low_bit == i32::MAX {
            return Some(([0.0; 3], 1.0)); // all zero
        }
        let step = 2f64.powi(low_bit);
        if step == 0.0 || !step.is_normal() {
            return None;
        }
        let fits = (0..3).all(|k| {
            // Every coordinate is k·step with |k| < 2^52 (so differences of
            // coordinates are exact) and the extent is below 2^9 steps.
            (hi[k] - lo[k]) / step < 512.0
                && lo[k].abs() / step < 4.5e15
                && hi[k].abs() / step < 4.5e15
        });
        fits.then_some((lo, step))
    }

    /// A key of point `p` of a set with [`SmallGrid::frame`] `(lo, step)`
    /// that orders the set lexicographically: its grid coordinates, each
    /// below 2^9 and exact (`p − lo` is a multiple of `step` below 2^9
    /// steps, and dividing by a power of two is exact), packed x first.
    #[inline]
    pub(crate) fn lex_key(p: &Point3, lo: &[f64; 3], step: f64) -> u64 {
        let g = |k: usize| ((p[k] - lo[k]) / step) as u64;
        g(0) << 18 | g(1) << 9 | g(2)
    }
}

impl Kernel for SmallGrid {
    #[inline(always)]
    fn orient3d(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> i32 {
        -sign(orient_det(&diffs3(a, b, c, d)))
    }
    #[inline(always)]
    fn insphere(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> i32 {
        -sign(insphere_det(&diffs4(a, b, c, d, e)))
    }
    // Both determinants are exact here, so the quick stage is the whole
    // predicate (a tie gives 0).
    const QUICK_IS_EXACT: bool = true;
    #[inline(always)]
    fn orient3d_quick(a: &Point3, b: &Point3, c: &Point3, d: &Point3, _: &StaticFilter) -> i32 {
        Self::orient3d(a, b, c, d)
    }
    #[inline(always)]
    fn insphere_quick(
        a: &Point3,
        b: &Point3,
        c: &Point3,
        d: &Point3,
        e: &Point3,
        _: &StaticFilter,
    ) -> i32 {
        Self::insphere(a, b, c, d, e)
    }
}

/// Exact 2D orientation of the projections of `a, b, c` onto coordinates
/// `(i, j)`: sign of `det[b − a, c − a]` in that plane.
#[inline]
pub fn orient2d_proj(a: &Point3, b: &Point3, c: &Point3, i: usize, j: usize) -> Sign {
    let pa = Coord { x: a[i], y: a[j] };
    let pb = Coord { x: b[i], y: b[j] };
    let pc = Coord { x: c[i], y: c[j] };
    // robust::orient2d is positive when a, b, c are counter-clockwise.
    Sign::of(robust::orient2d(pa, pb, pc))
}

/// CGAL's `coplanar_orientation(p, q, r)` for three points: the 2D
/// orientation in the first of the projections xy, yz, xz that is not
/// degenerate; `0` exactly when the three points are collinear.
///
/// For points in a common plane the same projection is chosen for every
/// non-collinear triple, so the signs are coherent within the plane.
#[inline]
pub fn coplanar_orientation(p: &Point3, q: &Point3, r: &Point3) -> Sign {
    let o = orient2d_proj(p, q, r, 0, 1);
    if o != Sign::Zero {
        return o;
    }
    let o = orient2d_proj(p, q, r, 1, 2);
    if o != Sign::Zero {
        return o;
    }
    orient2d_proj(p, q, r, 0, 2)
}

/// Whether three points are collinear (exactly).
#[inline]
pub fn collinear(p: &Point3, q: &Point3, r: &Point3) -> bool {
    coplanar_orientation(p, q, r) == Sign::Zero
}

/// Exact side of the coplanar point `p` with respect to the circle through
/// the non-collinear points `p0, p1, p2` (all four coplanar): `1` strictly
/// inside the disk, `-1` strictly outside, `0` on the circle.
///
/// Computed as an in-sphere test against any sphere through the circle: the
/// sphere through `p0, p1, p2` and a point `x` off their plane cuts the plane
/// exactly in their circumcircle, so for the coplanar `p` the two tests agree.
pub fn coplanar_side_of_bounded_circle(p0: &Point3, p1: &Point3, p2: &Point3, p: &Point3) -> Sign {
    // Move p0 along an axis that is not parallel to the plane. The xy
    // projection of the triangle is non-degenerate iff the plane's normal
    // has a non-zero z component, and so on.
    let k = if orient2d_proj(p0, p1, p2, 0, 1) != Sign::Zero {
        2
    } else if orient2d_proj(p0, p1, p2, 1, 2) != Sign::Zero {
        0
    } else {
        1
    };
    let mut x = *p0;
    x[k] = p0[k] + p0[k].abs().max(1.0);
    let o = orient3d(p0, p1, p2, &x);
    debug_assert!(o != Sign::Zero);
    insphere(p0, p1, p2, &x, p) * o
}

/// Strict lexicographic order on points: compare x, then y, then z.
/// CGAL's `Perturbation_order` (`compare_xyz`).
#[inline(always)]
pub fn lex_less(a: &Point3, b: &Point3) -> bool {
    if a[0] != b[0] {
        return a[0] < b[0];
    }
    if a[1] != b[1] {
        return a[1] < b[1];
    }
    a[2] < b[2]
}

/// [`lex_less`] evaluated without branches (the points must be finite).
#[inline(always)]
fn lex_less_branchless(a: &Point3, b: &Point3) -> bool {
    (a[0] < b[0]) | ((a[0] == b[0]) & ((a[1] < b[1]) | ((a[1] == b[1]) & (a[2] < b[2]))))
}

/// In-sphere test with CGAL's symbolic perturbation (Devillers & Teillaud):
/// never returns 0 for five distinct points with `(a, b, c, d)` positively
/// oriented. `1` means `e` is (perturbed-)inside.
///
/// On an exact tie the five points are ranked lexicographically and
/// examined from the largest down: if it is `e`, `e` is outside; if it is
/// tet vertex `i`, the orientation of the tet with vertex `i` replaced by
/// `e` decides, unless it is zero, in which case the next point is looked
/// at. This reproduces CGAL 5.5's `side_of_oriented_sphere(..., perturb = true)`.
#[inline(always)]
pub fn insphere_perturbed(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> Sign {
    let s = insphere_with(a, b, c, d, e, f64::INFINITY);
    Sign::of_i32(if s != 0 {
        s
    } else {
        insphere_tie::<Filtered>(a, b, c, d, e)
    })
}

/// [`insphere_perturbed`] with the predicates of kernel `K` and a static
/// filter for the point set, as an integer sign.
#[inline(always)]
pub(crate) fn insphere_perturbed_k<K: Kernel>(
    a: &Point3,
    b: &Point3,
    c: &Point3,
    d: &Point3,
    e: &Point3,
    filter: &StaticFilter,
) -> i32 {
    let s = K::insphere_static(a, b, c, d, e, filter);
    if s != 0 {
        return s;
    }
    insphere_tie::<K>(a, b, c, d, e)
}

/// The symbolic perturbation of [`insphere_perturbed`] on an exact tie.
#[cold]
#[inline(never)]
fn insphere_tie<K: Kernel>(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> i32 {
    let pts: [&Point3; 5] = [a, b, c, d, e];
    tie_by::<K>(pts, |i, j| lex_less_branchless(pts[i], pts[j]))
}

/// [`insphere_tie`] for points whose lexicographic order is already known
/// as integer keys: `keys[i] < keys[j]` exactly when point `i` is
/// lexicographically smaller than point `j` (as [`SmallGrid::lex_key`]
/// gives), so each comparison is one integer compare. Same result.
#[inline(never)]
pub(crate) fn insphere_tie_keyed<K: Kernel>(pts: [&Point3; 5], keys: [u64; 5]) -> i32 {
    tie_by::<K>(pts, |i, j| keys[i] < keys[j])
}

/// The tie rule over points `a, b, c, d, e` (`e` the query) given their
/// lexicographic comparison `less(i, j)`.
#[inline(always)]
fn tie_by<K: Kernel>(pts: [&Point3; 5], less: impl Fn(usize, usize) -> bool) -> i32 {
    let [a, b, c, d, e] = pts;
    // Visit the points from the lexicographically largest down. The
    // largest usually decides alone, so it is found first by a
    // tournament; the full ranking is only computed when its orientation
    // is zero. Comparisons are without branches: on degenerate inputs such
    // as grids nearly every in-sphere test is a tie, and comparisons of
    // equal coordinates mispredict.
    let larger = |i: usize, j: usize| {
        if less(i, j) {
            j
        } else {
            i
        }
    };
    let top = larger(larger(larger(0, 1), larger(2, 3)), 4);
    if top == 4 {
        return -1;
    }
    let mut q = [a, b, c, d];
    q[top] = e;
    let o = K::orient3d(q[0], q[1], q[2], q[3]);
    if o != 0 {
        return o;
    }
    // The rank of each point (how many of the others are larger).
    let mut above = [0usize; 5];
    for i in 0..5 {
        for j in i + 1..5 {
            let lt = less(i, j) as usize;
            above[i] += lt;
            above[j] += 1 - lt;
        }
    }
    // (Distinct points have distinct ranks 0..5; the mask only drops the
    // bounds check.)
    let mut by_rank = [4usize; 8];
    for (i, &r) in above.iter().enumerate() {
        by_rank[r & 7] = i;
    }
    for &i in &by_rank[1..5] {
        if i == 4 {
            return -1;
        }
        let mut q = [a, b, c, d];
        q[i] = e;
        let o = K::orient3d(q[0], q[1], q[2], q[3]);
        if o != 0 {
            return o;
        }
    }
    // Unreachable for distinct points and a non-degenerate tetrahedron.
    -1
}

/// Coplanar in-circle test with CGAL's symbolic perturbation
/// (`coplanar_side_of_bounded_circle(..., perturb = true)`): `1` if `p` is
/// (perturbed-)inside the circle through `p0, p1, p2`, else `-1`. The four
/// points must be coplanar and distinct, and `p0, p1, p2` not collinear.
pub fn coplanar_incircle_perturbed(p0: &Point3, p1: &Point3, p2: &Point3, p: &Point3) -> Sign {
    let s = coplanar_side_of_bounded_circle(p0, p1, p2, p);
    if s != Sign::Zero {
        return s;
    }
    let pts: [&Point3; 4] = [p0, p1, p2, p];
    let mut idx = [0usize, 1, 2, 3];
    for i in 1..4 {
        let mut j = i;
        while j > 0 && lex_less(pts[idx[j - 1]], pts[idx[j]]) {
            idx.swap(j - 1, j);
            j -= 1;
        }
    }
    let local = coplanar_orientation(p0, p1, p2);
    for &i in &idx[..3] {
        if i == 3 {
            return Sign::Negative;
        }
        let mut q = [p0, p1, p2];
        q[i] = p;
        let o = coplanar_orientation(q[0], q[1], q[2]);
        if o != Sign::Zero {
            return o * local;
        }
    }
    Sign::Negative
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    // The tests compare signs as integers (and with `robust`'s).
    fn orient3d(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> i32 {
        super::orient3d(a, b, c, d).to_i32()
    }
    fn insphere(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> i32 {
        super::insphere(a, b, c, d, e).to_i32()
    }
    fn insphere_perturbed(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> i32 {
        super::insphere_perturbed(a, b, c, d, e).to_i32()
    }
    fn coplanar_side_of_bounded_circle(p0: &Point3, p1: &Point3, p2: &Point3, p: &Point3) -> i32 {
        super::coplanar_side_of_bounded_circle(p0, p1, p2, p).to_i32()
    }

    fn det3(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0])
    }

    #[test]
    fn orient_matches_naive_on_small_integers() {
        // Small integers: the naive determinant is exact.
        let mut rng = SplitMix64::new(12345u64);
        let mut next = || ((rng.next_u64() >> 33) % 7) as f64 - 3.0;
        for _ in 0..5000 {
            let p: Vec<[f64; 3]> = (0..5).map(|_| [next(), next(), next()]).collect();
            let sub = |u: [f64; 3], v: [f64; 3]| [u[0] - v[0], u[1] - v[1], u[2] - v[2]];
            let naive = det3(sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0]));
            assert_eq!(orient3d(&p[0], &p[1], &p[2], &p[3]), sign(naive));
            // insphere via the lifted 4x4 determinant relative to e.
            let o = orient3d(&p[0], &p[1], &p[2], &p[3]);
            if o != 0 {
                let e = p[4];
                let row = |q: [f64; 3]| {
                    let d = sub(q, e);
                    [d[0], d[1], d[2], d[0] * d[0] + d[1] * d[1] + d[2] * d[2]]
                };
                let m = [row(p[0]), row(p[1]), row(p[2]), row(p[3])];
                // 4x4 determinant by cofactor expansion along the last column.
                let minor = |skip: usize| {
                    let r: Vec<[f64; 3]> = (0..4)
                        .filter(|&i| i != skip)
                        .map(|i| [m[i][0], m[i][1], m[i][2]])
                        .collect();
                    det3(r[0], r[1], r[2])
                };
                let mut d4 = 0.0;
                for (i, mi) in m.iter().enumerate() {
                    let s = if (i + 3) % 2 == 0 { 1.0 } else { -1.0 };
                    d4 += s * mi[3] * minor(i);
                }
                // det[rows a-e, b-e, c-e, d-e | lift]: positive for e inside when
                // orient3d_shewchuk(a,b,c,d) > 0 i.e. CGAL-negative. So
                // CGAL-inside = -sign(d4) * o ... check both orientations.
                let expected = -sign(d4);
                assert_eq!(insphere(&p[0], &p[1], &p[2], &p[3], &e), expected);
            }
        }
    }

    #[test]
    fn integer_stage_agrees_with_robust() {
        let mut rng = SplitMix64::new(99u64);
        let mut next = |range: u64| (rng.next_u64() >> 33) % range;
        let mut used = 0;
        for round in 0..20000 {
            // Dyadic grids of various scales and offsets, some near the
            // 23-bit limit, some beyond it (then the stage must decline).
            let bits = [3u64, 10, 20, 22, 23, 24][round % 6];
            let scale = [1.0, 0.125, 1024.0, 3.0][round % 4];
            let offset = [0.0, 1e6, -37.5][round % 3];
            let pts: Vec<[f64; 3]> = (0..5)
                .map(|_| {
                    let mut p = [0.0; 3];
                    for c in &mut p {
                        *c =
                            offset + scale * (next(1 << bits) as f64 - (1u64 << (bits - 1)) as f64);
                    }
                    p
                })
                .collect();
            let (a, b, c, d, e) = (&pts[0], &pts[1], &pts[2], &pts[3], &pts[4]);
            let o_ref = sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)));
            if let Some(o) = orient3d_int(a, b, c, d) {
                assert_eq!(o, o_ref);
                used += 1;
            }
            let i_ref = sign(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)));
            if let Some(i) = insphere_int(a, b, c, d, e) {
                assert_eq!(i, i_ref, "{pts:?}");
            }
            // Force coplanar / cospherical configurations too.
            let e2 = [a[0], b[1], c[2]];
            let f_ref = sign(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(&e2)));
            if let Some(i) = insphere_int(a, b, c, d, &e2) {
                assert_eq!(i, f_ref);
            }
        }
        assert!(used > 5000, "integer stage used {used} times");
        // Cube corners: exact zeros.
        let z = [0.0, 0.0, 0.0];
        assert_eq!(
            insphere_int(
                &z,
                &[1.0, 0.0, 0.0],
                &[0.0, 1.0, 0.0],
                &[0.0, 0.0, 1.0],
                &[1.0, 1.0, 1.0]
            ),
            Some(0)
        );
        assert_eq!(
            orient3d_int(&z, &[1.0, 0.0, 0.0], &[0.0, 1.0, 0.0], &[1.0, 1.0, 0.0]),
            Some(0)
        );
    }

    #[test]
    fn small_integer_shortcut_rejects_rounded_differences() {
        // d = 1e-20 makes every difference round to an integer, but the
        // points are not integers: the true orientation is not zero.
        let a = [3.0, 0.0, 0.0];
        let b = [0.0, 3.0, 0.0];
        let c = [0.0, 0.0, 3.0];
        let d = [1.0, 1.0, 1.0 + 1e-15];
        let naive_zero = [1.0, 1.0, 1.0];
        assert_eq!(orient3d(&a, &b, &c, &naive_zero), 0);
        assert_eq!(orient3d(&a, &b, &c, &d), 1);
        assert_eq!(
            orient3d(&a, &b, &c, &d),
            -sign(robust::orient3d(c3(&a), c3(&b), c3(&c), c3(&d)))
        );
        let tiny = [1e-20, 0.0, 0.0];
        let s = orient3d(&[3.0, 1.0, 0.0], &[0.0, 3.0, 1.0], &[1.0, 0.0, 3.0], &tiny);
        assert_eq!(
            s,
            -sign(robust::orient3d(
                c3(&[3.0, 1.0, 0.0]),
                c3(&[0.0, 3.0, 1.0]),
                c3(&[1.0, 0.0, 3.0]),
                c3(&tiny)
            ))
        );
        // Cospherical cube corners with e off by 1e-20 in x.
        let t = [
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let e = [1.0 + 0.0, 1.0, 1.0];
        assert_eq!(insphere(&t[0], &t[1], &t[2], &t[3], &e), 0);
        let e2 = [1e-20, 1.0, 1.0];
        let r = -sign(robust::insphere(
            c3(&t[0]),
            c3(&t[1]),
            c3(&t[2]),
            c3(&t[3]),
            c3(&e2),
        ));
        assert_eq!(insphere(&t[0], &t[1], &t[2], &t[3], &e2), r);
    }

    #[test]
    fn small_grid_kernel_agrees_with_filtered() {
        let mut rng = SplitMix64::new(5u64);
        let mut next = |m: u64| (rng.next_u64() >> 33) % m;
        for round in 0..20000 {
            let step = [1.0, 0.25, 8.0][round % 3];
            let offset = [0.0, 1024.0, -3.0 * 1024.0 * 1024.0][round % 3];
            let pts: Vec<[f64; 3]> = (0..5)
                .map(|_| {
                    [0; 3].map(|_: i32| {
                        offset + step * (next(511) as f64 - (round % 2) as f64 * 200.0)
                    })
                })
                .collect();
            assert!(SmallGrid::applies(&pts), "{pts:?}");
            let (a, b, c, d, e) = (&pts[0], &pts[1], &pts[2], &pts[3], &pts[4]);
            assert_eq!(SmallGrid::orient3d(a, b, c, d), orient3d(a, b, c, d));
            assert_eq!(SmallGrid::insphere(a, b, c, d, e), insphere(a, b, c, d, e));
        }
        assert!(!SmallGrid::applies(&[[0.0, 0.0, 0.0], [513.0, 0.0, 0.0]]));
        assert!(SmallGrid::applies(&[[0.0, 0.0, 0.0], [512.0, 0.0, 0.0]])); // step 512
        assert!(SmallGrid::applies(&[[0.0, 0.0, 0.0], [511.0, 0.0, 0.0]]));
        assert!(!SmallGrid::applies(&[[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]]));
        assert!(SmallGrid::applies(&[
            [1e6, 0.0, 0.0],
            [1e6 + 5.0, 0.5, 0.0]
        ]));
        // Over several chunks of the scan: a coarse first chunk refined
        // later still fits; a grid spoilt by its last point does not.
        let coarse_then_fine: Vec<Point3> = (0..600)
            .map(|i| {
                let x = if i < 300 {
                    8 * (i % 32)
                } else {
                    2 * (i % 128) + 1
                };
                [x as f64, (i % 7) as f64, 0.0]
            })
            .collect();
        assert_eq!(SmallGrid::frame(&coarse_then_fine), Some(([0.0; 3], 1.0)));
        let mut spoilt = coarse_then_fine.clone();
        spoilt.push([0.5, 0.0, 700.0]);
        assert!(!SmallGrid::applies(&spoilt));
        spoilt.pop();
        spoilt.push([0.25, 0.0, 0.0]);
        assert!(!SmallGrid::applies(&spoilt)); // 255 / 0.25 ≥ 512 steps
    }

    #[test]
    fn static_filter_agrees_with_exact() {
        // Near-cospherical and near-coplanar tuples at several scales and
        // offsets, judged with the static bound of the whole set: the
        // answer must be the exact one. The plain determinant gets many of
        // these wrong (counted), so a bound that is too small fails here.
        let mut rng = SplitMix64::new(77u64);
        let mut unif = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let mut plain_wrong = 0;
        for (scale, offset) in [
            (1.0, 0.0),
            (1e-12, 0.0),
            (1e12, 0.0),
            (1.0, 1e6),
            (1e-3, 7.0),
        ] {
            let mut pts = Vec::new();
            for _ in 0..400 {
                // A point on the unit sphere (rounded), mapped to the scale.
                let (u, v) = (unif() * 2.0 - 1.0, unif() * std::f64::consts::TAU);
                let r = (1.0 - u * u).sqrt();
                pts.push([r * v.cos(), r * v.sin(), u].map(|c| offset + scale * c));
            }
            // The corners of the set's box, so the bound covers them.
            pts.push([offset - scale; 3]);
            pts.push([offset + scale; 3]);
            let filter = StaticFilter::for_points(&pts);
            for k in 0..2000 {
                let i = |j: usize| &pts[(k * 7 + j * 131 + j * j * 17) % 400];
                let (a, b, c, d, e) = (i(0), i(1), i(2), i(3), i(4));
                let exact = -sign(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)));
                assert_eq!(Filtered::insphere_static(a, b, c, d, e, &filter), exact);
                if -sign(insphere_det(&diffs4(a, b, c, d, e))) != exact {
                    plain_wrong += 1;
                }
                // Coplanar-ish: the midpoint of a and b against a, b, c.
                let m = [0, 1, 2].map(|j| 0.5 * (a[j] + b[j]));
                let exact = -sign(robust::orient3d(c3(a), c3(b), c3(c), c3(&m)));
                assert_eq!(Filtered::orient3d_static(a, b, c, &m, &filter), exact);
                if -sign(orient_det(&diffs3(a, b, c, &m))) != exact {
                    plain_wrong += 1;
                }
            }
        }
        assert!(plain_wrong > 100, "only {plain_wrong} hard cases");
        assert_eq!(StaticFilter::for_points(&[]), StaticFilter::NONE);
        // Underflowing bounds are disabled rather than trusted.
        let tiny = StaticFilter::for_box(&[0.0; 3], &[1e-80; 3]);
        assert_eq!(tiny, StaticFilter::NONE);
    }

    #[test]
    fn insphere_sign_convention() {
        let t = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert_eq!(orient3d(&t[0], &t[1], &t[2], &t[3]), 1);
        assert_eq!(insphere(&t[0], &t[1], &t[2], &t[3], &[0.1, 0.1, 0.1]), 1);
        // Negatively oriented: reversed.
        assert_eq!(insphere(&t[1], &t[0], &t[2], &t[3], &[0.1, 0.1, 0.1]), -1);
    }

    #[test]
    fn orient_exact_near_degenerate() {
        // Points on a line y = x in a plane z = 0 with tiny perturbations
        // beyond double precision of the naive formula.
        let a = [0.5, 0.5, 0.0];
        let b = [12.0, 12.0, 0.0];
        let c = [24.0, 24.0, 0.0];
        let d = [0.5 + 1e-15, 0.5, 1e-300];
        // d above the plane z=0 by a tiny amount but abc collinear -> 0.
        assert_eq!(orient3d(&a, &b, &c, &d), 0);
        let c2 = [24.0, 24.0 + 2f64.powi(-48), 0.0];
        let o = orient3d(&a, &b, &c2, &[0.0, 0.0, 1.0]);
        assert_ne!(o, 0);
    }

    #[test]
    fn coplanar_circle() {
        // (triangle, query, expected side): planes z = 0, x = 1 (needs the
        // yz projection) and y = 3 (needs xz); a reversed triangle gives
        // the same answer.
        let xy = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let yx = [[2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let x1 = [[1.0, 0.0, 0.0], [1.0, 2.0, 0.0], [1.0, 0.0, 2.0]];
        let y3 = [[0.0, 3.0, 0.0], [2.0, 3.0, 0.0], [0.0, 3.0, 2.0]];
        let cases = [
            (xy, [1.0, 1.0, 0.0], 1),
            (xy, [2.0, 2.0, 0.0], 0),
            (xy, [3.0, 3.0, 0.0], -1),
            (yx, [1.0, 1.0, 0.0], 1),
            (x1, [1.0, 1.0, 1.0], 1),
            (x1, [1.0, 2.0, 2.0], 0),
            (x1, [1.0, 5.0, 2.0], -1),
            (y3, [1.0, 3.0, 1.0], 1),
            (y3, [2.0, 3.0, 2.0], 0),
            (y3, [5.0, 3.0, 5.0], -1),
        ];
        for (t, q, want) in cases {
            assert_eq!(
                coplanar_side_of_bounded_circle(&t[0], &t[1], &t[2], &q),
                want,
                "{t:?} {q:?}"
            );
        }
    }

    #[test]
    fn perturbed_never_zero_on_cube() {
        let cube: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        // A positively oriented tet of cube corners and the other corners.
        let (a, b, c, d) = (cube[0], cube[1], cube[2], cube[4]);
        assert_eq!(orient3d(&a, &b, &c, &d), 1);
        for e in &cube[..] {
            if [a, b, c, d].contains(e) {
                continue;
            }
            assert_eq!(insphere(&a, &b, &c, &d, e), 0);
            assert_ne!(insphere_perturbed(&a, &b, &c, &d, e), 0);
        }
        // (1,1,1) is lexicographically the largest: it is outside.
        assert_eq!(insphere_perturbed(&a, &b, &c, &d, &cube[7]), -1);
    }

    /// Five distinct points whose first four are not coplanar, with the
    /// first two swapped if needed to orient them positively, when the
    /// fifth is exactly on their sphere (an in-sphere tie); else `None`.
    fn tie_tuple(p: [&Point3; 5]) -> Option<[&Point3; 5]> {
        if (0..5).any(|i| (i + 1..5).any(|j| p[i] == p[j])) {
            return None;
        }
        let [mut a, mut b, c, d, e] = p;
        match orient3d(a, b, c, d) {
            0 => return None,
            o if o < 0 => std::mem::swap(&mut a, &mut b),
            _ => {}
        }
        (insphere(a, b, c, d, e) == 0).then_some([a, b, c, d, e])
    }

    /// The symbolic rule written the plain way: sort the five points
    /// lexicographically, then apply the rule from the largest down.
    fn insphere_tie_by_sorting(pts: [&Point3; 5]) -> i32 {
        let mut idx = [0usize, 1, 2, 3, 4];
        idx.sort_by(|&i, &j| {
            if lex_less(pts[j], pts[i]) {
                std::cmp::Ordering::Less
            } else {
                std::cmp::Ordering::Greater
            }
        });
        for i in idx {
            if i == 4 {
                return -1;
            }
            let mut q = [pts[0], pts[1], pts[2], pts[3]];
            q[i] = pts[4];
            let o = orient3d(q[0], q[1], q[2], q[3]);
            if o != 0 {
                return o;
            }
        }
        -1
    }

    #[test]
    fn branchless_tie_ranking_matches_sorting() {
        // Points of a small grid with negative coordinates and -0.0, so
        // that many 5-tuples are cospherical and share coordinates at
        // every level of the lexicographic order.
        let vals: [f64; 5] = [-1.0, -0.0, 0.0, 1.0, 2.0];
        let mut grid: Vec<Point3> = Vec::new();
        for x in vals {
            for y in vals {
                for z in vals {
                    // (-0.0 == 0.0: the first of equal points is kept.)
                    if !grid.contains(&[x, y, z]) {
                        grid.push([x, y, z]);
                    }
                }
            }
        }
        let mut rng = SplitMix64::new(0x1234_5678u64);
        let mut next = |n: usize| ((rng.next_u64() >> 33) % n as u64) as usize;
        let (mut ties, mut decided_late) = (0, 0);
        while ties < 3000 {
            let mut t = [0usize; 5];
            for k in 0..5 {
                t[k] = next(grid.len());
            }
            let Some([a, b, c, d, e]) = tie_tuple(t.map(|k| &grid[k])) else {
                continue;
            };
            ties += 1;
            let want = insphere_tie_by_sorting([a, b, c, d, e]);
            let mut first = [a, b, c, d];
            let largest = (0..4).fold(0, |m, k| if lex_less(first[m], first[k]) { k } else { m });
            // (When the query is the largest, the first step decides.)
            if lex_less(e, first[largest]) {
                first[largest] = e;
                if orient3d(first[0], first[1], first[2], first[3]) == 0 {
                    decided_late += 1;
                }
            }
            assert_eq!(
                insphere_perturbed(a, b, c, d, e),
                want,
                "{a:?} {b:?} {c:?} {d:?} {e:?}"
            );
        }
        // The sample reaches the rule's later steps, not only the first.
        assert!(decided_late > 20, "{decided_late}");
    }

    /// The grid keys order a small-grid set as `lex_less` does, and the
    /// keyed tie-break agrees with the plain one on every tie, including
    /// those decided after the first step.
    #[test]
    fn keyed_tie_matches_lex_tie() {
        // A dyadic grid (step 1/4) shifted to negative and large offsets.
        let mut rng = SplitMix64::new(0x9e37_79b9u64);
        let mut next = |n: u64| (rng.next_u64() >> 33) % n;
        for offset in [0.0, -3.25, 1e6] {
            let grid: Vec<Point3> = (0..200)
                .map(|_| {
                    let mut c = || offset + 0.25 * next(6) as f64 - 0.5;
                    [c(), c(), c()]
                })
                .collect();
            let (lo, step) = SmallGrid::frame(&grid).expect("a small grid");
            let key = |p: &Point3| SmallGrid::lex_key(p, &lo, step);
            for p in &grid {
                for q in &grid {
                    assert_eq!(key(p) < key(q), lex_less(p, q), "{p:?} {q:?}");
                }
            }
            let (mut ties, mut tries) = (0, 0);
            while ties < 2000 {
                tries += 1;
                assert!(tries < 10_000_000);
                let drawn = [0; 5].map(|_| &grid[next(200) as usize]);
                let Some(pts) = tie_tuple(drawn) else {
                    continue;
                };
                ties += 1;
                let [a, b, c, d, e] = pts;
                assert_eq!(
                    insphere_tie_keyed::<SmallGrid>(pts, pts.map(key)),
                    insphere_perturbed(a, b, c, d, e),
                    "{pts:?}"
                );
            }
        }
    }

    #[test]
    fn quick_stages_agree_with_the_full_predicates() {
        // Random points, and points near a common sphere and plane, where
        // the static stage must often abstain. Whenever a quick stage
        // answers, it equals the full predicate.
        let mut rng = SplitMix64::new(0x9e37_79b9u64);
        let mut unif = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let filter = StaticFilter::for_box(&[-2.0; 3], &[2.0; 3]);
        let (mut decided, mut abstained) = (0, 0);
        for round in 0..20_000 {
            let mut p = [[0.0; 3]; 5];
            for q in &mut p {
                if round % 2 == 0 {
                    *q = [unif() * 2.0 - 1.0, unif() * 2.0 - 1.0, unif() * 2.0 - 1.0];
                } else {
                    // Near the unit sphere's equator, in the plane z ≈ 0.
                    let t = unif() * std::f64::consts::TAU;
                    *q = [t.cos(), t.sin(), (unif() - 0.5) * 1e-15];
                }
            }
            let [a, b, c, d, e] = &p;
            let o = Filtered::orient3d_quick(a, b, c, d, &filter);
            if o != 0 {
                assert_eq!(o, Filtered::orient3d_static(a, b, c, d, &filter));
                assert_eq!(o, orient3d(a, b, c, d));
            }
            let s = Filtered::insphere_quick(a, b, c, d, e, &filter);
            if s != 0 {
                decided += 1;
                assert_eq!(s, Filtered::insphere_static(a, b, c, d, e, &filter));
                assert_eq!(s, insphere(a, b, c, d, e));
            } else {
                abstained += 1;
            }
        }
        assert!(decided > 5000 && abstained > 5000, "{decided} {abstained}");
        // On a small grid the quick stage is exact: it answers 0 only on
        // ties.
        let g = |i: u32| [(i % 3) as f64, ((i / 3) % 3) as f64, (i / 9) as f64];
        for i in 0..27u32 {
            let (a, b, c, d, e) = (
                g(i),
                g((i * 7 + 1) % 27),
                g((i * 11 + 5) % 27),
                g((i * 5 + 3) % 27),
                g((i * 13 + 2) % 27),
            );
            assert_eq!(
                SmallGrid::insphere_quick(&a, &b, &c, &d, &e, &filter),
                insphere(&a, &b, &c, &d, &e)
            );
            assert_eq!(
                SmallGrid::orient3d_quick(&a, &b, &c, &d, &filter),
                orient3d(&a, &b, &c, &d)
            );
        }
    }

    /// The cases of a corpus file: coordinates, then Shewchuk's sign.
    fn corpus(text: &str) -> Vec<(Vec<f64>, i32)> {
        text.lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| {
                let v: Vec<f64> = l
                    .split_whitespace()
                    .skip(1)
                    .map(|t| t.parse().unwrap())
                    .collect();
                let (sign, coords) = v.split_last().unwrap();
                (coords.to_vec(), *sign as i32)
            })
            .collect()
    }

    fn points(c: &[f64], dim: usize) -> Vec<Point3> {
        c.chunks(dim)
            .map(|p| [p[0], p[1], if dim == 3 { p[2] } else { 0.0 }])
            .collect()
    }

    /// Nanevski et al.'s hard cases (coordinates from 1e-4 to 1e33, see
    /// `tests/fixtures/predicates/README.md`): `orient3d` through every
    /// path of the crate (the public predicate, the filtered kernel with
    /// and without the static bound of the case's own box, and its quick
    /// stage whenever it answers) gives the corpus's sign.
    #[test]
    fn robust_corpus_orient3d() {
        let cases = corpus(include_str!("../../tests/fixtures/predicates/orient3d.txt"));
        assert_eq!(cases.len(), 1000);
        let mut quick = 0;
        for (k, (c, want)) in cases.iter().enumerate() {
            let p = points(c, 3);
            let (a, b, cc, d) = (&p[0], &p[1], &p[2], &p[3]);
            // Shewchuk's orient3d is this crate's negated.
            let want = -want;
            assert_eq!(orient3d(a, b, cc, d), want, "case {}", k + 1);
            let filter = StaticFilter::for_points(&p);
            assert_eq!(Filtered::orient3d(a, b, cc, d), want, "case {}", k + 1);
            assert_eq!(Filtered::orient3d_static(a, b, cc, d, &filter), want);
            let q = Filtered::orient3d_quick(a, b, cc, d, &filter);
            if q != 0 {
                quick += 1;
                assert_eq!(q, want, "case {}", k + 1);
            }
            // Swapping two points reverses the sign.
            assert_eq!(orient3d(b, a, cc, d), -want, "case {}", k + 1);
        }
        assert!(quick > 0);
    }

    /// As [`robust_corpus_orient3d`], for `insphere` and its perturbed
    /// form (which only differs on ties, and there are none).
    #[test]
    fn robust_corpus_insphere() {
        let cases = corpus(include_str!("../../tests/fixtures/predicates/insphere.txt"));
        assert_eq!(cases.len(), 1000);
        for (k, (c, want)) in cases.iter().enumerate() {
            let p = points(c, 3);
            let (a, b, cc, d, e) = (&p[0], &p[1], &p[2], &p[3], &p[4]);
            let want = -want;
            assert_eq!(insphere(a, b, cc, d, e), want, "case {}", k + 1);
            assert_eq!(insphere_perturbed(a, b, cc, d, e), want, "case {}", k + 1);
            let filter = StaticFilter::for_points(&p);
            assert_eq!(Filtered::insphere(a, b, cc, d, e), want);
            assert_eq!(Filtered::insphere_static(a, b, cc, d, e, &filter), want);
            let q = Filtered::insphere_quick(a, b, cc, d, e, &filter);
            assert!(q == 0 || q == want, "case {}", k + 1);
            assert_eq!(insphere(b, a, cc, d, e), -want, "case {}", k + 1);
        }
    }

    /// The 2D cases through the crate's projections: `orient2d` as the xy
    /// orientation of points at z = 0, and `incircle` as the coplanar
    /// circle test (inside means the corpus's sign times the orientation
    /// of the first three points).
    #[test]
    fn robust_corpus_orient2d_and_incircle() {
        let cases = corpus(include_str!("../../tests/fixtures/predicates/orient2d.txt"));
        assert_eq!(cases.len(), 1000);
        for (k, (c, want)) in cases.iter().enumerate() {
            let p = points(c, 2);
            let got = orient2d_proj(&p[0], &p[1], &p[2], 0, 1).to_i32();
            assert_eq!(got, *want, "case {}", k + 1);
            assert_eq!(coplanar_orientation(&p[0], &p[1], &p[2]).to_i32(), *want);
        }
        let cases = corpus(include_str!("../../tests/fixtures/predicates/incircle.txt"));
        assert_eq!(cases.len(), 1000);
        for (k, (c, want)) in cases.iter().enumerate() {
            let p = points(c, 2);
            let o = orient2d_proj(&p[0], &p[1], &p[2], 0, 1).to_i32();
            let got = coplanar_side_of_bounded_circle(&p[0], &p[1], &p[2], &p[3]);
            assert_eq!(got, want * o, "case {}", k + 1);
            let perturbed = super::coplanar_incircle_perturbed(&p[0], &p[1], &p[2], &p[3]);
            assert_eq!(perturbed.to_i32(), want * o, "case {}", k + 1);
        }
    }
}
