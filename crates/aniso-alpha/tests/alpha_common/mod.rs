//! Helpers for the alpha-shape tests: an exact integer oracle for the
//! Gabriel predicates, brute-force empty-ball oracles, random points.
#![allow(dead_code, clippy::needless_range_loop)]

use std::cmp::Ordering;

/// A signed big integer (sign + magnitude in base 2^32), just enough for
/// exact polynomial signs: add, sub, mul.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Big {
    neg: bool,
    mag: Vec<u32>, // little-endian, no trailing zeros
}

impl Big {
    pub fn zero() -> Self {
        Big {
            neg: false,
            mag: Vec::new(),
        }
    }
    fn trim(mut self) -> Self {
        while self.mag.last() == Some(&0) {
            self.mag.pop();
        }
        if self.mag.is_empty() {
            self.neg = false;
        }
        self
    }
    /// `m · 2^shift` for `shift ≥ 0`.
    pub fn from_parts(neg: bool, m: u64, shift: u32) -> Self {
        let words = (shift / 32) as usize;
        let bits = shift % 32;
        let mut mag = vec![0u32; words];
        let v = (m as u128) << bits;
        for k in 0..4 {
            mag.push((v >> (32 * k)) as u32);
        }
        Big { neg, mag }.trim()
    }
    pub fn signum(&self) -> i32 {
        if self.mag.is_empty() {
            0
        } else if self.neg {
            -1
        } else {
            1
        }
    }
    fn cmp_mag(a: &[u32], b: &[u32]) -> Ordering {
        if a.len() != b.len() {
            return a.len().cmp(&b.len());
        }
        for k in (0..a.len()).rev() {
            if a[k] != b[k] {
                return a[k].cmp(&b[k]);
            }
        }
        Ordering::Equal
    }
    fn add_mag(a: &[u32], b: &[u32]) -> Vec<u32> {
        let mut out = Vec::with_capacity(a.len().max(b.len()) + 1);
        let mut carry = 0u64;
        for k in 0..a.len().max(b.len()) {
            let s = *a.get(k).unwrap_or(&0) as u64 + *b.get(k).unwrap_or(&0) as u64 + carry;
            out.push(s as u32);
            carry = s >> 32;
        }
        out.push(carry as u32);
        out
    }
    /// |a| − |b| for |a| ≥ |b|.
    fn sub_mag(a: &[u32], b: &[u32]) -> Vec<u32> {
        let mut out = Vec::with_capacity(a.len());
        let mut borrow = 0i64;
        for k in 0..a.len() {
            let mut d = a[k] as i64 - *b.get(k).unwrap_or(&0) as i64 - borrow;
            borrow = 0;
            if d < 0 {
                d += 1 << 32;
                borrow = 1;
            }
            out.push(d as u32);
        }
        out
    }
    pub fn add(&self, o: &Big) -> Big {
        if self.neg == o.neg {
            return Big {
                neg: self.neg,
                mag: Self::add_mag(&self.mag, &o.mag),
            }
            .trim();
        }
        match Self::cmp_mag(&self.mag, &o.mag) {
            Ordering::Equal => Big::zero(),
            Ordering::Greater => Big {
                neg: self.neg,
                mag: Self::sub_mag(&self.mag, &o.mag),
            }
            .trim(),
            Ordering::Less => Big {
                neg: o.neg,
                mag: Self::sub_mag(&o.mag, &self.mag),
            }
            .trim(),
        }
    }
    pub fn neg(&self) -> Big {
        Big {
            neg: !self.neg,
            mag: self.mag.clone(),
        }
        .trim()
    }
    pub fn sub(&self, o: &Big) -> Big {
        self.add(&o.neg())
    }
    pub fn mul(&self, o: &Big) -> Big {
        let mut out = vec![0u64; self.mag.len() + o.mag.len() + 1];
        for (i, &x) in self.mag.iter().enumerate() {
            let mut carry = 0u64;
            for (j, &y) in o.mag.iter().enumerate() {
                let t = out[i + j] + x as u64 * y as u64 + carry;
                out[i + j] = t & 0xffff_ffff;
                carry = t >> 32;
            }
            let mut k = i + o.mag.len();
            while carry != 0 {
                let t = out[k] + carry;
                out[k] = t & 0xffff_ffff;
                carry = t >> 32;
                k += 1;
            }
        }
        Big {
            neg: self.neg != o.neg,
            mag: out.into_iter().map(|x| x as u32).collect(),
        }
        .trim()
    }
}

/// Exact integer images of doubles: every value is `k · 2^e0` for the
/// smallest exponent `e0` among them; returns the `k`s (positive scaling
/// keeps the signs of homogeneous polynomials).
pub fn to_ints(xs: &[f64]) -> Vec<Big> {
    let parts: Vec<(bool, u64, i32)> = xs
        .iter()
        .map(|&x| {
            if x == 0.0 {
                return (false, 0, i32::MAX);
            }
            let bits = x.to_bits();
            let exp = ((bits >> 52) & 0x7ff) as i32;
            let frac = bits & ((1u64 << 52) - 1);
            let (m, e) = if exp == 0 {
                (frac, -1074)
            } else {
                (frac | (1 << 52), exp - 1075)
            };
            (x < 0.0, m, e)
        })
        .collect();
    let e0 = parts.iter().map(|p| p.2).min().unwrap_or(0);
    parts
        .iter()
        .map(|&(neg, m, e)| {
            if m == 0 {
                Big::zero()
            } else {
                Big::from_parts(neg, m, (e - e0) as u32)
            }
        })
        .collect()
}

fn dot(a: &[Big; 3], b: &[Big; 3]) -> Big {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

/// Exact sign of `(p − a)·(p − b)`.
pub fn oracle_edge(a: &[f64; 3], b: &[f64; 3], p: &[f64; 3]) -> i32 {
    let all: Vec<f64> = a.iter().chain(b).chain(p).copied().collect();
    let z = to_ints(&all);
    let mut s = Big::zero();
    for k in 0..3 {
        let x = z[6 + k].sub(&z[k]);
        let y = z[6 + k].sub(&z[3 + k]);
        s = s.add(&x.mul(&y));
    }
    s.signum()
}

/// Exact sign of `|p − c0|² − R²` for the circumcircle (c0, R) of `abc`,
/// computed independently of the library's formula: with u = b − a,
/// v = c − a, w = p − a, the circumcentre offset is o = (α u + β v) / (2 nn)
/// where α = |v|²(|u|² − u·v), β = |u|²(|v|² − u·v), nn = |u|²|v|² − (u·v)²;
/// sign(|w − o|² − |o|²) = sign(4nn²|w|² − 4nn (w·(αu + βv))) = sign(nn|w|²
/// − w·(αu + βv)) — the same polynomial, derived here from the solved 2x2
/// system o·u = |u|²/2, o·v = |v|²/2 and checked by that system.
pub fn oracle_triangle(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], p: &[f64; 3]) -> i32 {
    let all: Vec<f64> = a.iter().chain(b).chain(c).chain(p).copied().collect();
    let z = to_ints(&all);
    let d = |i: usize| -> [Big; 3] { std::array::from_fn(|k| z[3 * i + k].sub(&z[k])) };
    let (u, v, w) = (d(1), d(2), d(3));
    let (uu, vv, uv, ww, wu, wv) = (
        dot(&u, &u),
        dot(&v, &v),
        dot(&u, &v),
        dot(&w, &w),
        dot(&w, &u),
        dot(&w, &v),
    );
    let nn = uu.mul(&vv).sub(&uv.mul(&uv));
    // 2·nn·o = α u + β v with (Cramer on o·u = uu/2, o·v = vv/2):
    // α = (uu·vv − vv·uv) = vv (uu − uv), β = uu (vv − uv).
    let alpha = vv.mul(&uu.sub(&uv));
    let beta = uu.mul(&vv.sub(&uv));
    // Check the solution: (αu + βv)·u = nn·uu and (αu + βv)·v = nn·vv.
    assert_eq!(alpha.mul(&uu).add(&beta.mul(&uv)), nn.mul(&uu));
    assert_eq!(alpha.mul(&uv).add(&beta.mul(&vv)), nn.mul(&vv));
    // |w − o|² − |o|² = |w|² − 2 w·o = (nn|w|² − w·(αu + βv)) / nn.
    ww.mul(&nn)
        .sub(&alpha.mul(&wu))
        .sub(&beta.mul(&wv))
        .signum()
}

/// Deterministic PRNG (SplitMix64), shared with the other tests.
pub use crate::common::Rng;

pub fn random_points(seed: u64, n: usize) -> Vec<[f64; 3]> {
    let mut r = Rng::new(seed);
    (0..n)
        .map(|_| [r.uniform(), r.uniform(), r.uniform()])
        .collect()
}

use aniso_alpha::geometry::{cross, dot as dotf, sub};

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = dotf(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

/// Whether the open ball (c, α) is empty of `pts` except for `skip`
/// (with a relative slack for rounding).
fn ball_empty(pts: &[[f64; 3]], skip: &[usize], c: &[f64; 3], alpha: f64) -> bool {
    let a2 = alpha * alpha * (1.0 - 1e-11);
    pts.iter().enumerate().all(|(k, p)| {
        if skip.contains(&k) {
            return true;
        }
        let d = sub(*p, *c);
        dotf(d, d) >= a2
    })
}

/// Brute force: is there an empty open ball of radius `alpha` whose sphere
/// passes through points `i` and `j`? The centres lie on a circle in the
/// bisector plane; each other point excludes an arc of it, so the feasible
/// set is tested between consecutive arc endpoints.
pub fn edge_exposed(pts: &[[f64; 3]], i: usize, j: usize, alpha: f64) -> bool {
    let (a, b) = (&pts[i], &pts[j]);
    let m = [
        (a[0] + b[0]) / 2.0,
        (a[1] + b[1]) / 2.0,
        (a[2] + b[2]) / 2.0,
    ];
    let d = sub(*b, *a);
    let h2 = dotf(d, d) / 4.0;
    if alpha * alpha < h2 {
        return false;
    }
    let s = (alpha * alpha - h2).sqrt();
    let dn = unit(d);
    let helper = if dn[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = unit(cross(dn, helper));
    let e2 = cross(dn, e1);
    let centre = |th: f64| {
        let (c, sn) = (th.cos(), th.sin());
        [
            m[0] + s * (c * e1[0] + sn * e2[0]),
            m[1] + s * (c * e1[1] + sn * e2[1]),
            m[2] + s * (c * e1[2] + sn * e2[2]),
        ]
    };
    let mut angles = vec![0.0];
    for (k, p) in pts.iter().enumerate() {
        if k == i || k == j {
            continue;
        }
        // |c(θ) − p|² − α² = C + A cos θ + B sin θ
        let mp = sub(m, *p);
        let cc = dotf(mp, mp) + s * s - alpha * alpha;
        let aa = 2.0 * s * dotf(mp, e1);
        let bb = 2.0 * s * dotf(mp, e2);
        let r = (aa * aa + bb * bb).sqrt();
        if r > 0.0 && cc.abs() <= r {
            let phi = bb.atan2(aa);
            let delta = (-cc / r).acos();
            angles.push(phi + delta);
            angles.push(phi - delta);
        }
    }
    let tau = std::f64::consts::TAU;
    let mut angles: Vec<f64> = angles.into_iter().map(|x| x.rem_euclid(tau)).collect();
    angles.sort_by(f64::total_cmp);
    let n = angles.len();
    (0..n).any(|k| {
        let lo = angles[k];
        let hi = if k + 1 < n {
            angles[k + 1]
        } else {
            angles[0] + tau
        };
        ball_empty(pts, &[i, j], &centre((lo + hi) / 2.0), alpha)
    })
}

/// Brute force: is there an empty open ball of radius `alpha` whose sphere
/// passes through points `i`, `j`, `k`? Its centre is one of the two points
/// at distance α from them on the line through the circumcentre.
pub fn triangle_exposed(pts: &[[f64; 3]], i: usize, j: usize, k: usize, alpha: f64) -> bool {
    let a = &pts[i];
    let u = sub(pts[j], *a);
    let v = sub(pts[k], *a);
    let n = cross(u, v);
    let nn = dotf(n, n);
    let (uu, vv) = (dotf(u, u), dotf(v, v));
    let vn = cross(v, n);
    let nu = cross(n, u);
    let o: [f64; 3] = std::array::from_fn(|q| (uu * vn[q] + vv * nu[q]) / (2.0 * nn));
    let c0 = [a[0] + o[0], a[1] + o[1], a[2] + o[2]];
    let r2 = dotf(o, o);
    if alpha * alpha < r2 {
        return false;
    }
    let t = (alpha * alpha - r2).sqrt();
    let nh = unit(n);
    [1.0, -1.0].iter().any(|&sg| {
        let c = [
            c0[0] + sg * t * nh[0],
            c0[1] + sg * t * nh[1],
            c0[2] + sg * t * nh[2],
        ];
        ball_empty(pts, &[i, j, k], &c, alpha)
    })
}
