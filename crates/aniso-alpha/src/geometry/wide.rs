//! The wide-integer stage of the exact predicates: when the coordinates of
//! a predicate's points, written as integers times one common power of
//! two, need at most [`WIDE_BITS`] bits, both determinants are evaluated
//! exactly in fixed-size multi-limb integers.
//!
//! This is the stage for nearly degenerate configurations of ordinary
//! decimal data (e.g. points near a line, rounded to 1e-6), where the
//! determinant is far below its error bound, so every float filter fails,
//! but the coordinates share an exponent range of a few dozen bits. There
//! the adaptive expansion arithmetic of `robust` reaches its exact stage,
//! which is an order of magnitude slower than these few hundred limb
//! products. Inputs whose exponents span more bits (coordinates from
//! 1e-30 to 1e30 in one test) go on to `robust`.

/// The most bits the coordinates of one predicate may span (from the
/// highest bit of the largest magnitude to the lowest set bit of any
/// coordinate) for this stage. Differences then have at most
/// `WIDE_BITS + 1` bits and the in-sphere determinant, of degree 5, at
/// most `5 · (WIDE_BITS + 2) + 3` < 64 · [`LIMBS`].
pub(super) const WIDE_BITS: i32 = 100;

/// Limbs of a [`Wide`] integer.
const LIMBS: usize = 9;

/// A signed integer of up to `64 · LIMBS` bits, sign and magnitude
/// (little-endian limbs, `len` of them used, no leading zero limb).
#[derive(Clone, Copy, Debug)]
pub(super) struct Wide {
    mag: [u64; LIMBS],
    len: usize,
    neg: bool,
}

impl Wide {
    const ZERO: Wide = Wide {
        mag: [0; LIMBS],
        len: 0,
        neg: false,
    };

    pub(super) fn from_i128(x: i128) -> Wide {
        let m = x.unsigned_abs();
        let mut w = Wide::ZERO;
        w.mag[0] = m as u64;
        w.mag[1] = (m >> 64) as u64;
        w.len = if w.mag[1] != 0 {
            2
        } else {
            (w.mag[0] != 0) as usize
        };
        w.neg = x < 0 && w.len > 0;
        w
    }

    /// The sign: `1`, `0` or `-1`.
    pub(super) fn signum(&self) -> i32 {
        if self.len == 0 {
            0
        } else if self.neg {
            -1
        } else {
            1
        }
    }

    fn trim(mut self) -> Wide {
        while self.len > 0 && self.mag[self.len - 1] == 0 {
            self.len -= 1;
        }
        if self.len == 0 {
            self.neg = false;
        }
        self
    }

    /// `self · other` (the product must fit in [`LIMBS`] limbs, which the
    /// bound on [`WIDE_BITS`] guarantees for the determinants).
    pub(super) fn mul(&self, other: &Wide) -> Wide {
        let mut r = Wide::ZERO;
        if self.len == 0 || other.len == 0 {
            return r;
        }
        debug_assert!(self.len + other.len <= LIMBS);
        for i in 0..self.len {
            let mut carry = 0u128;
            let a = self.mag[i] as u128;
            for j in 0..other.len {
                let k = i + j;
                let t = a * other.mag[j] as u128 + r.mag[k] as u128 + carry;
                r.mag[k] = t as u64;
                carry = t >> 64;
            }
            let k = i + other.len;
            if k < LIMBS {
                r.mag[k] = carry as u64;
            }
        }
        r.len = (self.len + other.len).min(LIMBS);
        r.neg = self.neg != other.neg;
        r.trim()
    }

    /// Compares magnitudes.
    fn cmp_mag(&self, other: &Wide) -> std::cmp::Ordering {
        if self.len != other.len {
            return self.len.cmp(&other.len);
        }
        for k in (0..self.len).rev() {
            if self.mag[k] != other.mag[k] {
                return self.mag[k].cmp(&other.mag[k]);
            }
        }
        std::cmp::Ordering::Equal
    }

    /// `self + other`.
    pub(super) fn add(&self, other: &Wide) -> Wide {
        if other.len == 0 {
            return *self;
        }
        if self.len == 0 {
            return *other;
        }
        let mut r = Wide::ZERO;
        if self.neg == other.neg {
            let n = self.len.max(other.len);
            let mut carry = 0u64;
            for k in 0..n {
                let (s, c1) = self.mag[k].overflowing_add(other.mag[k]);
                let (s, c2) = s.overflowing_add(carry);
                r.mag[k] = s;
                carry = (c1 | c2) as u64;
            }
            r.len = n;
            if carry != 0 {
                debug_assert!(n < LIMBS);
                r.mag[n.min(LIMBS - 1)] = carry;
                r.len = (n + 1).min(LIMBS);
            }
            r.neg = self.neg;
            return r;
        }
        // Opposite signs: the larger magnitude minus the smaller.
        let (big, small) = match self.cmp_mag(other) {
            std::cmp::Ordering::Equal => return Wide::ZERO,
            std::cmp::Ordering::Greater => (self, other),
            std::cmp::Ordering::Less => (other, self),
        };
        let mut borrow = 0u64;
        for k in 0..big.len {
            let (d, b1) = big.mag[k].overflowing_sub(small.mag[k]);
            let (d, b2) = d.overflowing_sub(borrow);
            r.mag[k] = d;
            borrow = (b1 | b2) as u64;
        }
        r.len = big.len;
        r.neg = big.neg;
        r.trim()
    }

    /// `self − other`.
    pub(super) fn sub(&self, other: &Wide) -> Wide {
        let mut o = *other;
        o.neg = !o.neg && o.len > 0;
        self.add(&o)
    }
}

/// The coordinates of `points` as integers `k` with `coordinate = k · 2^L`
/// for one common `L`, if every coordinate is finite and normal (or zero)
/// and they span at most [`WIDE_BITS`] bits.
pub(super) fn common_ints<const N: usize>(points: [&[f64; 3]; N]) -> Option<[[i128; 3]; N]> {
    let mut lo = i32::MAX;
    let mut hi = i32::MIN;
    for p in &points {
        for &x in p.iter() {
            if x == 0.0 {
                continue;
            }
            let bits = x.to_bits();
            let exp = ((bits >> 52) & 0x7ff) as i32;
            if exp == 0 || exp == 0x7ff {
                return None;
            }
            let mant = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
            lo = lo.min(exp - 1075 + mant.trailing_zeros() as i32);
            hi = hi.max(exp - 1075 + 53);
        }
    }
    if lo == i32::MAX {
        return Some([[0; 3]; N]);
    }
    if hi - lo > WIDE_BITS {
        return None;
    }
    let int = |x: f64| -> i128 {
        if x == 0.0 {
            return 0;
        }
        let bits = x.to_bits();
        let exp = ((bits >> 52) & 0x7ff) as i32;
        let mant = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
        // x = mant · 2^(exp − 1075) = k · 2^lo; the shift is exact in
        // either direction (the low bits shifted out are zero).
        let shift = exp - 1075 - lo;
        let k = if shift >= 0 {
            (mant as i128) << shift
        } else {
            (mant >> (-shift)) as i128
        };
        if x < 0.0 {
            -k
        } else {
            k
        }
    };
    Some(points.map(|p| p.map(int)))
}

/// The span below which [`orient3d_wide`] and [`insphere_wide`] take the
/// narrow path: differences below 2^61, 2×2 minors below 2^123, lifts
/// below 2^124, 3×3 minors below 2^186 (three `u64` limbs) and the
/// in-sphere determinant below 2^312 (five limbs), with margin for the
/// sign bit at every level.
const NARROW_BITS: i32 = 60;

/// Two's-complement integers of 3 and 5 limbs (little-endian).
type I192 = [u64; 3];
type I320 = [u64; 5];

/// `|a| · |b|` as an unsigned 192-bit number (`|b| < 2^128`).
#[inline(always)]
fn mul_u64_u128(a: u64, b: u128) -> I192 {
    let lo = a as u128 * (b as u64) as u128;
    let hi = a as u128 * ((b >> 64) as u64) as u128;
    let mid = (lo >> 64) + (hi as u64) as u128;
    [lo as u64, mid as u64, ((hi >> 64) + (mid >> 64)) as u64]
}

/// The two's complement of `x` (its negation).
#[inline(always)]
fn neg<const N: usize>(x: [u64; N]) -> [u64; N] {
    let mut r = [0u64; N];
    let mut carry = 1u64;
    for k in 0..N {
        let (v, c) = (!x[k]).overflowing_add(carry);
        r[k] = v;
        carry = c as u64;
    }
    r
}

/// `x + y` (two's complement; the true sum must fit).
#[inline(always)]
fn add<const N: usize>(x: [u64; N], y: [u64; N]) -> [u64; N] {
    let mut r = [0u64; N];
    let mut carry = false;
    for k in 0..N {
        let (v, c1) = x[k].overflowing_add(y[k]);
        let (v, c2) = v.overflowing_add(carry as u64);
        r[k] = v;
        carry = c1 | c2;
    }
    r
}

/// `a · b` as a 192-bit two's-complement integer (`|b| < 2^127`).
#[inline(always)]
fn mul_i64_i128(a: i64, b: i128) -> I192 {
    let m = mul_u64_u128(a.unsigned_abs(), b.unsigned_abs());
    if (a < 0) != (b < 0) {
        neg(m)
    } else {
        m
    }
}

/// `a · b` for `a ≥ 0` below 2^128 and `b` a 192-bit two's-complement
/// integer, as 320 bits (the true product must fit).
#[inline(always)]
fn mul_u128_i192(a: u128, b: I192) -> I320 {
    let negative = b[2] >> 63 != 0;
    let m = if negative { neg(b) } else { b };
    let a = [a as u64, (a >> 64) as u64];
    let mut r = [0u64; 5];
    for (i, &ai) in a.iter().enumerate() {
        let mut carry = 0u128;
        for (j, &mj) in m.iter().enumerate() {
            let t = ai as u128 * mj as u128 + r[i + j] as u128 + carry;
            r[i + j] = t as u64;
            carry = t >> 64;
        }
        r[i + 3] = carry as u64;
    }
    if negative {
        neg(r)
    } else {
        r
    }
}

/// The sign of a two's-complement integer.
#[inline(always)]
fn signum<const N: usize>(x: [u64; N]) -> i32 {
    if x[N - 1] >> 63 != 0 {
        -1
    } else {
        (x.iter().any(|&l| l != 0)) as i32
    }
}

/// The coordinates of `points` as `i64`s times one power of two, if they
/// span at most [`NARROW_BITS`] bits (see [`common_ints`]).
#[inline(always)]
fn narrow_ints<const N: usize>(points: [&[f64; 3]; N]) -> Option<[[i64; 3]; N]> {
    // Per coordinate: its biased exponent and 53-bit mantissa (0 for a
    // zero); the lowest set bit and the top of the span, both relative to
    // the exponent bias.
    let mut exp = [[0i32; 3]; N];
    let mut mant = [[0u64; 3]; N];
    let mut lo = i32::MAX;
    let mut hi = i32::MIN;
    for i in 0..N {
        for k in 0..3 {
            let x = points[i][k];
            let bits = x.to_bits();
            let e = ((bits >> 52) & 0x7ff) as i32;
            if e == 0x7ff || (e == 0 && x != 0.0) {
                return None;
            }
            if x != 0.0 {
                let m = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
                lo = lo.min(e + m.trailing_zeros() as i32);
                hi = hi.max(e + 53);
                exp[i][k] = e;
                mant[i][k] = m;
            }
        }
    }
    if hi - lo > NARROW_BITS {
        return (lo == i32::MAX).then_some([[0; 3]; N]);
    }
    let mut out = [[0i64; 3]; N];
    for i in 0..N {
        for k in 0..3 {
            // x = m · 2^(e − 1075) = k · 2^(lo − 1075), below 2^60; the
            // bits shifted out are zero, and the shift is within 0..=7 up
            // or 0..=52 down. (A zero has m = 0.)
            let (m, shift) = (mant[i][k], exp[i][k] - lo);
            let v = if m == 0 {
                0
            } else if shift >= 0 {
                (m << shift) as i64
            } else {
                (m >> (-shift)) as i64
            };
            out[i][k] = if points[i][k] < 0.0 { -v } else { v };
        }
    }
    Some(out)
}

/// Exact sign of Shewchuk's orient3d determinant, when the coordinates
/// span at most [`NARROW_BITS`] bits (the common case of the wide stage,
/// tried first).
#[inline]
pub(super) fn orient3d_narrow_f(
    a: &[f64; 3],
    b: &[f64; 3],
    c: &[f64; 3],
    d: &[f64; 3],
) -> Option<i32> {
    narrow_ints([a, b, c, d]).map(orient3d_narrow)
}

/// Exact sign of Shewchuk's insphere determinant, when the coordinates
/// span at most [`NARROW_BITS`] bits.
#[inline]
pub(super) fn insphere_narrow_f(
    a: &[f64; 3],
    b: &[f64; 3],
    c: &[f64; 3],
    d: &[f64; 3],
    e: &[f64; 3],
) -> Option<i32> {
    narrow_ints([a, b, c, d, e]).map(insphere_narrow)
}

/// [`orient3d_wide`] for coordinates within [`NARROW_BITS`].
#[inline]
fn orient3d_narrow(p: [[i64; 3]; 4]) -> i32 {
    let [a, b, c, d] = p;
    let r = |p: [i64; 3]| [p[0] - d[0], p[1] - d[1], p[2] - d[2]];
    let (a, b, c) = (r(a), r(b), r(c));
    let m = |u: [i64; 3], v: [i64; 3]| u[0] as i128 * v[1] as i128 - v[0] as i128 * u[1] as i128;
    let det = add(
        add(mul_i64_i128(a[2], m(b, c)), mul_i64_i128(b[2], m(c, a))),
        mul_i64_i128(c[2], m(a, b)),
    );
    signum(det)
}

/// [`insphere_wide`] for coordinates within [`NARROW_BITS`].
#[inline]
fn insphere_narrow(p: [[i64; 3]; 5]) -> i32 {
    let e = p[4];
    let q: [[i64; 3]; 4] =
        std::array::from_fn(|r| [p[r][0] - e[0], p[r][1] - e[1], p[r][2] - e[2]]);
    let x = |r: usize| q[r][0] as i128;
    let y = |r: usize| q[r][1] as i128;
    let z = |r: usize| q[r][2];
    let lift = |r: usize| {
        let [u, v, w] = q[r].map(|c| c.unsigned_abs() as u128);
        u * u + v * v + w * w
    };
    let xy = |r: usize, s: usize| x(r) * y(s) - x(s) * y(r);
    let ab = xy(0, 1);
    let bc = xy(1, 2);
    let cd = xy(2, 3);
    let da = xy(3, 0);
    let ac = xy(0, 2);
    let bd = xy(1, 3);
    // 3x3 minors z₀·m₀ + z₁·m₁ + z₂·m₂ with each 2x2 minor m split as
    // h·2^64 + l (h signed, l unsigned): Σ z·h < 3·2^120 and Σ z·l < 3·2^125
    // fit in i128, and the minor is (Σ z·h)·2^64 + Σ z·l, as 192 bits.
    let t3 = |t: [(i64, i128); 3]| {
        let (mut h, mut l) = (0i128, 0i128);
        for (z, m) in t {
            h += z as i128 * (m >> 64) as i64 as i128;
            l += z as i128 * (m as u64) as i128;
        }
        let l = [l as u64, (l >> 64) as u64, (l >> 127) as u64];
        add(l, [0, h as u64, (h >> 64) as u64])
    };
    let abc = t3([(z(0), bc), (-z(1), ac), (z(2), ab)]);
    let bcd = t3([(z(1), cd), (-z(2), bd), (z(3), bc)]);
    let cda = t3([(z(2), da), (z(3), ac), (z(0), cd)]);
    let dab = t3([(z(3), ab), (z(0), bd), (z(1), da)]);
    // The last level in floating point first: the minors are exact, and
    // on nearly degenerate input that is where the cancellation was, so
    // the four products rarely cancel much further. Each product is within
    // 3 roundings of the exact one (the conversions and the product), and
    // the sum adds 3 more: 1e-14 ≈ 45ε of the sum of magnitudes bounds the
    // error with margin. Else the exact products.
    let (l, m) = (
        [lift(3), lift(2), lift(1), lift(0)],
        [abc, neg(dab), cda, neg(bcd)],
    );
    let terms: [f64; 4] = std::array::from_fn(|i| u128_f64(l[i]) * to_f64(m[i]));
    let approx = (terms[0] + terms[1]) + (terms[2] + terms[3]);
    let bound = 1e-14 * (terms[0].abs() + terms[1].abs() + terms[2].abs() + terms[3].abs());
    if approx > bound {
        return 1;
    }
    if -approx > bound {
        return -1;
    }
    let det = add(
        add(mul_u128_i192(l[0], m[0]), mul_u128_i192(l[1], m[1])),
        add(mul_u128_i192(l[2], m[2]), mul_u128_i192(l[3], m[3])),
    );
    signum(det)
}

/// `x` rounded to `f64`, within 2 roundings.
#[inline(always)]
fn u128_f64(x: u128) -> f64 {
    (x >> 64) as u64 as f64 * 2f64.powi(64) + x as u64 as f64
}

/// A 192-bit two's-complement integer rounded to `f64`, within 3
/// roundings (its parts are added by magnitude, without cancellation).
#[inline(always)]
fn to_f64(x: I192) -> f64 {
    let negative = x[2] >> 63 != 0;
    let m = if negative { neg(x) } else { x };
    let v = (m[2] as f64 * 2f64.powi(64) + m[1] as f64) * 2f64.powi(64) + m[0] as f64;
    if negative {
        -v
    } else {
        v
    }
}

/// Exact sign of Shewchuk's orient3d determinant `det[a − d, b − d, c − d]`
/// by wide integers, when the coordinates allow.
pub(super) fn orient3d_wide(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], d: &[f64; 3]) -> Option<i32> {
    let [a, b, c, d] = common_ints([a, b, c, d])?;
    let w = |p: &[i128; 3], k: usize| Wide::from_i128(p[k] - d[k]);
    let (ax, ay, az) = (w(&a, 0), w(&a, 1), w(&a, 2));
    let (bx, by, bz) = (w(&b, 0), w(&b, 1), w(&b, 2));
    let (cx, cy, cz) = (w(&c, 0), w(&c, 1), w(&c, 2));
    let m1 = bx.mul(&cy).sub(&cx.mul(&by));
    let m2 = cx.mul(&ay).sub(&ax.mul(&cy));
    let m3 = ax.mul(&by).sub(&bx.mul(&ay));
    let det = az.mul(&m1).add(&bz.mul(&m2)).add(&cz.mul(&m3));
    Some(det.signum())
}

/// Exact sign of Shewchuk's insphere determinant (points relative to `e`)
/// by wide integers, when the coordinates allow.
pub(super) fn insphere_wide(
    a: &[f64; 3],
    b: &[f64; 3],
    c: &[f64; 3],
    d: &[f64; 3],
    e: &[f64; 3],
) -> Option<i32> {
    let q = common_ints([a, b, c, d, e])?;
    let e = q[4];
    let rel: [[Wide; 3]; 4] =
        std::array::from_fn(|r| std::array::from_fn(|k| Wide::from_i128(q[r][k] - e[k])));
    let [x, y, z] = [0, 1, 2].map(|k| rel.map(|p| p[k]));
    let lift = |r: usize| x[r].mul(&x[r]).add(&y[r].mul(&y[r])).add(&z[r].mul(&z[r]));
    let xy = |r: usize, s: usize| x[r].mul(&y[s]).sub(&x[s].mul(&y[r]));
    let ab = xy(0, 1);
    let bc = xy(1, 2);
    let cd = xy(2, 3);
    let da = xy(3, 0);
    let ac = xy(0, 2);
    let bd = xy(1, 3);
    let abc = z[0].mul(&bc).sub(&z[1].mul(&ac)).add(&z[2].mul(&ab));
    let bcd = z[1].mul(&cd).sub(&z[2].mul(&bd)).add(&z[3].mul(&bc));
    let cda = z[2].mul(&da).add(&z[3].mul(&ac)).add(&z[0].mul(&cd));
    let dab = z[3].mul(&ab).add(&z[0].mul(&bd)).add(&z[1].mul(&da));
    let det = lift(3)
        .mul(&abc)
        .sub(&lift(2).mul(&dab))
        .add(&lift(1).mul(&cda).sub(&lift(0).mul(&bcd)));
    Some(det.signum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    fn sign(x: f64) -> i32 {
        (x > 0.0) as i32 - (x < 0.0) as i32
    }

    fn c3(p: &[f64; 3]) -> robust::Coord3D<f64> {
        robust::Coord3D {
            x: p[0],
            y: p[1],
            z: p[2],
        }
    }

    /// Wide integers against i128 on values where i128 is exact.
    #[test]
    fn arithmetic_matches_i128() {
        let mut rng = SplitMix64::new(1);
        for _ in 0..20000 {
            let bits = 1 + rng.below(62) as u32;
            let mut r = || (rng.next_u64() >> (64 - bits)) as i64 as i128 - (1i128 << (bits - 1));
            let (a, b, c) = (r(), r(), r());
            let (wa, wb, wc) = (Wide::from_i128(a), Wide::from_i128(b), Wide::from_i128(c));
            assert_eq!(wa.mul(&wb).signum(), (a * b).signum() as i32);
            assert_eq!(wa.add(&wb).signum(), (a + b).signum() as i32);
            assert_eq!(wa.sub(&wb).signum(), (a - b).signum() as i32);
            let x = a * b - c * a + b;
            let wx = wa.mul(&wb).sub(&wc.mul(&wa)).add(&wb);
            assert_eq!(wx.signum(), x.signum() as i32, "{a} {b} {c}");
            // Equal magnitudes cancel to zero.
            assert_eq!(wx.sub(&wx).signum(), 0);
        }
        // Carries across limbs: (2^64 − 1)² + 1 and (2^127 − 1) · 2.
        let m = Wide::from_i128(u64::MAX as i128);
        let sq = m.mul(&m);
        assert_eq!(sq.len, 2);
        assert_eq!(sq.add(&Wide::from_i128(2 * u64::MAX as i128 + 1)).len, 3);
        let big = Wide::from_i128(i128::MAX);
        let twice = big.add(&big);
        assert_eq!(
            (twice.len, twice.mag[1], twice.mag[0]),
            (2, u64::MAX, u64::MAX - 1)
        );
        assert_eq!(twice.sub(&big).sub(&big).signum(), 0);
    }

    /// Points near a line and near a sphere, rounded to a decimal step as
    /// real data are: the wide stage answers and agrees with `robust`,
    /// including on the exact ties it finds.
    #[test]
    fn wide_stage_agrees_with_robust_on_near_degenerate_points() {
        let mut rng = SplitMix64::new(2);
        let (mut answered, mut ties) = (0, 0);
        for it in 0..20000 {
            let step = [1e-6, 1e-3, 0.1][it % 3];
            let round = |x: f64| (x / step).round() * step;
            let dir = [1.0, 0.7, 0.3];
            let mut p = [[0.0; 3]; 5];
            for q in p.iter_mut() {
                let t = rng.uniform() * if it % 2 == 0 { 1.0 } else { 1e3 };
                *q = dir.map(|d| round(d * t));
            }
            let [a, b, c, d, e] = p.each_ref();
            if let Some(s) = insphere_wide(a, b, c, d, e) {
                answered += 1;
                ties += (s == 0) as usize;
                let want = sign(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)));
                assert_eq!(s, want, "{p:?}");
                if let Some(n) = insphere_narrow_f(a, b, c, d, e) {
                    assert_eq!(n, want, "{p:?}");
                }
            }
            if let Some(s) = orient3d_wide(a, b, c, d) {
                let want = sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)));
                assert_eq!(s, want, "{p:?}");
                if let Some(n) = orient3d_narrow_f(a, b, c, d) {
                    assert_eq!(n, want, "{p:?}");
                }
            }
        }
        assert!(answered > 15000, "{answered}");
        assert!(ties > 0);
    }

    /// The narrow path (coordinates within 60 bits) and the general wide
    /// one agree, at the narrow path's extremes too.
    #[test]
    fn narrow_and_wide_paths_agree() {
        let mut rng = SplitMix64::new(3);
        let mut narrow = 0;
        for it in 0..20000 {
            // Coordinates with up to 60 significant bits in one frame: an
            // integer part and a dyadic fraction, often near the limits.
            let bits = [8, 30, 52, 59, 60][it % 5];
            let top = 1i64 << (bits - 1);
            let p: [[f64; 3]; 5] = std::array::from_fn(|_| {
                std::array::from_fn(|_| {
                    let k = match rng.below(3) {
                        0 => top - 1 - rng.below(4) as i64,
                        1 => -(top - 1) + rng.below(4) as i64,
                        _ => (rng.next_u64() >> (65 - bits)) as i64 - (top >> 1),
                    };
                    // k · 2^-20: exactly representable (|k| < 2^60 needs
                    // at most 53 significant bits only when the low bits
                    // are zero: round k to 53 bits).
                    let k = if bits > 53 {
                        (k >> (bits - 53)) << (bits - 53)
                    } else {
                        k
                    };
                    k as f64 * 2f64.powi(-20)
                })
            });
            let pts = p.each_ref();
            let wide_i = common_ints(pts).map(|q| {
                let e = q[4];
                let rel: [[Wide; 3]; 4] = std::array::from_fn(|r| {
                    std::array::from_fn(|k| Wide::from_i128(q[r][k] - e[k]))
                });
                rel
            });
            if let Some(n) = narrow_ints(pts) {
                narrow += 1;
                let s = insphere_narrow(n);
                let want = sign(robust::insphere(
                    c3(pts[0]),
                    c3(pts[1]),
                    c3(pts[2]),
                    c3(pts[3]),
                    c3(pts[4]),
                ));
                assert_eq!(s, want, "{p:?}");
                let o = orient3d_narrow([n[0], n[1], n[2], n[3]]);
                let want = sign(robust::orient3d(
                    c3(pts[0]),
                    c3(pts[1]),
                    c3(pts[2]),
                    c3(pts[3]),
                ));
                assert_eq!(o, want, "{p:?}");
            }
            assert!(wide_i.is_some());
        }
        assert!(narrow > 15000, "{narrow}");
        // Products at the top of the narrow range: (2^60 − 1)-sized
        // differences, whose 3x3 minors and determinant fill their limbs.
        let m = 2f64.powi(59);
        let corner = [[m, -m, m], [-m, m, m], [m, m, -m], [-m, -m, -m], [m, m, m]];
        let [a, b, c, d, e] = corner.each_ref();
        assert!(narrow_ints([a, b, c, d, e]).is_some());
        let want = sign(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)));
        assert_eq!(insphere_narrow_f(a, b, c, d, e), Some(want));
        assert_eq!(insphere_wide(a, b, c, d, e), Some(want));
    }

    /// Coordinates spanning more than [`WIDE_BITS`] bits are left to the
    /// next stage; within the span, the extremes are exact.
    #[test]
    fn span_bound() {
        let o = [0.0; 3];
        let (x, y) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // 1 has its bit at 2^0: with 2^(1 − WIDE_BITS) the span is
        // WIDE_BITS bits, one bit more is too many.
        let lo = 2f64.powi(1 - WIDE_BITS);
        let fits = [1.0, 1.0, lo];
        let want = sign(robust::orient3d(c3(&o), c3(&x), c3(&y), c3(&fits)));
        assert_eq!(orient3d_wide(&o, &x, &y, &fits), Some(want));
        assert_ne!(want, 0);
        let too_wide = [1.0, 1.0, lo / 2.0];
        assert_eq!(orient3d_wide(&o, &x, &y, &too_wide), None);
        assert_eq!(insphere_wide(&o, &x, &y, &fits, &[1.0, 1.0, 1e300]), None);
        // Subnormals and non-finite values are refused.
        assert_eq!(
            orient3d_wide(&o, &x, &y, &[0.0, 0.0, f64::MIN_POSITIVE / 2.0]),
            None
        );
        assert_eq!(orient3d_wide(&o, &x, &y, &[0.0, 0.0, f64::NAN]), None);
        // All zero.
        assert_eq!(insphere_wide(&o, &o, &o, &o, &o), Some(0));
    }
}
