//! Exact "strictly inside the smallest circumsphere" predicates for the
//! Gabriel tests of edges and triangles.
//!
//! Both are a floating-point evaluation with a static forward error bound
//! (the filter), backed by an exact evaluation in Shewchuk's expansion
//! arithmetic (error-free `two_sum` / `two_product` with Dekker splitting,
//! no fused multiply-add) when the filter cannot decide. The exact stage
//! computes every coordinate difference as a two-term expansion, so the
//! result is the exact sign of the polynomial for any finite `f64` input
//! (barring overflow or underflow of the intermediate products, i.e.
//! coordinates beyond about 1e±50, as for [`crate::geometry::predicates`]).
//!
//! * Edge `(a, b)`, point `p`: `p` is strictly inside the ball with diameter
//!   `ab` iff `(p − a)·(p − b) < 0` (Thales).
//! * Triangle `(a, b, c)`, point `p`: with `u = b − a`, `v = c − a`,
//!   `w = p − a`, the circumcentre of the triangle is `a + o` with
//!   `o = (|v|²(|u|² − u·v) u + |u|²(|v|² − u·v) v) / (2|u × v|²)`, and
//!   `|w − o|² − |o|² = |w|² − 2 w·o`. Multiplying by `|u × v|² > 0`,
//!   `p` is strictly inside the triangle's diametral sphere iff
//!   `D = |w|²·|u × v|² − (w·u)|v|²(|u|² − u·v) − (w·v)|u|²(|v|² − u·v) < 0`,
//!   a polynomial of degree 6 in the coordinate differences, with
//!   `|u × v|² = |u|²|v|² − (u·v)²` (Lagrange).

use crate::geometry::{cross, cross_permanent, dot, Point3, Sign};

/// Sign of `(p − a)·(p − b)`: negative when `p` is strictly inside the
/// ball with diameter `ab`, zero on its sphere, positive outside.
///
/// ```
/// use aniso_alpha::alpha::exact::edge_diametral_side;
/// use aniso_alpha::geometry::Sign;
/// let (a, b) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
/// assert_eq!(edge_diametral_side(&a, &b, &[1.0, 0.5, 0.0]), Sign::Negative);
/// assert_eq!(edge_diametral_side(&a, &b, &[1.0, 1.0, 0.0]), Sign::Zero);
/// assert_eq!(edge_diametral_side(&a, &b, &[1.0, 1.5, 0.0]), Sign::Positive);
/// ```
#[inline]
pub fn edge_diametral_side(a: &Point3, b: &Point3, p: &Point3) -> Sign {
    let mut d = 0.0;
    let mut m = 0.0;
    for k in 0..3 {
        let x = p[k] - a[k];
        let y = p[k] - b[k];
        d += x * y;
        m += (x * y).abs();
    }
    // Depth 4 (difference, product, two sums): the error is below 4.5ε·m;
    // 2e-15 ≈ 9ε leaves margin for the rounding of m itself.
    let eps = 2e-15 * m;
    if d > eps {
        return Sign::Positive;
    }
    if -d > eps {
        return Sign::Negative;
    }
    Sign::of_i32(edge_exact(a, b, p))
}

/// Sign of `D` (see the module docs): negative when `p` is strictly inside
/// the smallest circumsphere (diametral sphere) of the non-degenerate
/// triangle `abc`, zero on it, positive outside.
///
/// ```
/// use aniso_alpha::alpha::exact::triangle_diametral_side;
/// use aniso_alpha::geometry::Sign;
/// let (a, b, c) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
/// // Circumcentre (1, 1, 0), radius √2.
/// assert_eq!(triangle_diametral_side(&a, &b, &c, &[1.0, 1.0, 1.0]), Sign::Negative);
/// assert_eq!(triangle_diametral_side(&a, &b, &c, &[2.0, 2.0, 0.0]), Sign::Zero);
/// assert_eq!(triangle_diametral_side(&a, &b, &c, &[1.0, 1.0, 2.0]), Sign::Positive);
/// ```
#[inline]
pub fn triangle_diametral_side(a: &Point3, b: &Point3, c: &Point3, p: &Point3) -> Sign {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    let vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let ww = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    let uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let wu = w[0] * u[0] + w[1] * u[1] + w[2] * u[2];
    let wv = w[0] * v[0] + w[1] * v[1] + w[2] * v[2];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    let d = ww * nn - wu * vv * (uu - uv) - wv * uu * (vv - uv);
    // Semi-static stage: with M the largest |coordinate difference| in u, v,
    // w, the permanent below is at most 144·M⁶ (ww ≤ 3M², its |u × v|²
    // permanent ≤ 12M⁴, the other two terms ≤ 54M⁶ each), so 4e-15·144 =
    // 5.8e-13 times M⁶ bounds the error.
    let m = u[0]
        .abs()
        .max(u[1].abs())
        .max(u[2].abs())
        .max(v[0].abs().max(v[1].abs()).max(v[2].abs()))
        .max(w[0].abs().max(w[1].abs()).max(w[2].abs()));
    let m2 = m * m;
    let eps = 5.8e-13 * (m2 * m2 * m2);
    if (f64::MIN_POSITIVE..f64::MAX).contains(&eps) {
        if d > eps {
            return Sign::Positive;
        }
        if -d > eps {
            return Sign::Negative;
        }
    }
    Sign::of_i32(
        triangle_filter(&u, &v, &w, uu, vv, ww, d).unwrap_or_else(|| triangle_exact(a, b, c, p)),
    )
}

/// The filter of [`triangle_diametral_side`]: `Some(sign)` when the f64
/// value `d` is certainly of the right sign.
#[inline]
pub(crate) fn triangle_filter(
    u: &Point3,
    v: &Point3,
    w: &Point3,
    uu: f64,
    vv: f64,
    ww: f64,
    d: f64,
) -> Option<i32> {
    // Permanents: the same expression with absolute values everywhere.
    let puv = (u[0] * v[0]).abs() + (u[1] * v[1]).abs() + (u[2] * v[2]).abs();
    let pwu = (w[0] * u[0]).abs() + (w[1] * u[1]).abs() + (w[2] * u[2]).abs();
    let pwv = (w[0] * v[0]).abs() + (w[1] * v[1]).abs() + (w[2] * v[2]).abs();
    let n0 = (u[1] * v[2]).abs() + (u[2] * v[1]).abs();
    let n1 = (u[2] * v[0]).abs() + (u[0] * v[2]).abs();
    let n2 = (u[0] * v[1]).abs() + (u[1] * v[0]).abs();
    let pnn = n0 * n0 + n1 * n1 + n2 * n2;
    let m = ww * pnn + pwu * vv * (uu + puv) + pwv * uu * (vv + puv);
    // At most 10 rounded operations on any path from the inputs to `d`:
    // the error is below about 10ε·m. 4e-15 ≈ 18ε leaves ample margin.
    let eps = 4e-15 * m;
    if d > eps && eps >= f64::MIN_POSITIVE {
        Some(1)
    } else if -d > eps && eps >= f64::MIN_POSITIVE {
        Some(-1)
    } else {
        None
    }
}

#[cold]
#[inline(never)]
fn edge_exact(a: &Point3, b: &Point3, p: &Point3) -> i32 {
    let mut sum = Expansion::zero();
    for k in 0..3 {
        let x = Expansion::diff(p[k], a[k]);
        let y = Expansion::diff(p[k], b[k]);
        sum = sum.add(&x.mul(&y));
    }
    sum.sign()
}

#[cold]
#[inline(never)]
fn triangle_exact(a: &Point3, b: &Point3, c: &Point3, p: &Point3) -> i32 {
    let u: [Expansion; 3] = std::array::from_fn(|k| Expansion::diff(b[k], a[k]));
    let v: [Expansion; 3] = std::array::from_fn(|k| Expansion::diff(c[k], a[k]));
    let w: [Expansion; 3] = std::array::from_fn(|k| Expansion::diff(p[k], a[k]));
    let dot = |x: &[Expansion; 3], y: &[Expansion; 3]| {
        x[0].mul(&y[0]).add(&x[1].mul(&y[1])).add(&x[2].mul(&y[2]))
    };
    let uu = dot(&u, &u);
    let vv = dot(&v, &v);
    let ww = dot(&w, &w);
    let uv = dot(&u, &v);
    let wu = dot(&w, &u);
    let wv = dot(&w, &v);
    let nn = uu.mul(&vv).sub(&uv.mul(&uv));
    let t1 = ww.mul(&nn);
    let t2 = wu.mul(&vv).mul(&uu.sub(&uv));
    let t3 = wv.mul(&uu).mul(&vv.sub(&uv));
    t1.sub(&t2).sub(&t3).sign()
}

/// Squared circumradius of the tet `p`, accurate to a few ulps even for
/// slivers: `r² = |N|² / (4 det²)` with `det = u·(v × w)` and
/// `N = |u|²(v × w) + |v|²(w × u) + |w|²(u × v)` (`u, v, w` the edges from
/// `p[0]`). Both are evaluated in f64 with a forward error bound; when
/// either may have lost more than about 10 bits to cancellation (a flat or
/// nearly flat tet), they are recomputed exactly and only then rounded.
///
/// Returned with the tet's Gabriel mask: bit `i`
/// is set when `p[i]` is strictly inside the diametral sphere of the
/// opposite face `FACE[i]` (`[1, 3, 2]`, `[0, 2, 3]`, `[0, 3, 1]`,
/// `[0, 1, 2]`), i.e. `triangle_diametral_side(face…, p[i]) < 0`.
///
/// Faces 1–3 contain `p[0]`, so their tests share the edge vectors
/// `u, v, w` from `p[0]`, their dot products and cross products with the
/// radius computation: each `D` is evaluated with exactly the operations
/// [`triangle_diametral_side`] would use for that face, and the same
/// semi-static bound applies; undecided cases (and face 0) go through
/// [`triangle_diametral_side`].
#[inline]
pub(crate) fn cell_radius2_and_mask(p: [&Point3; 4]) -> (f64, u8) {
    let [a, b, c, d] = p;
    let f = TetFrame::new(p);
    let TetFrame {
        u,
        v,
        w,
        uu,
        vv,
        ww,
        cvw,
        cwu,
        cuv,
    } = f;
    let dot = |x: &Point3, y: &Point3| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (uv, vw, wu) = (dot(&u, &v), dot(&v, &w), dot(&w, &u));
    let (nvw, nwu, nuv) = (dot(&cvw, &cvw), dot(&cwu, &cwu), dot(&cuv, &cuv));
    let m = u[0]
        .abs()
        .max(u[1].abs())
        .max(u[2].abs())
        .max(v[0].abs().max(v[1].abs()).max(v[2].abs()))
        .max(w[0].abs().max(w[1].abs()).max(w[2].abs()));
    let m2 = m * m;
    let eps = 5.8e-13 * (m2 * m2 * m2);
    let ok = (f64::MIN_POSITIVE..f64::MAX).contains(&eps);
    // D for face 3 (a, b, c) + apex d, face 1 (a, c, d) + apex b, face 2
    // (a, d, b) + apex c, in `triangle_diametral_side`'s variable names.
    let d3 = ww * nuv - wu * vv * (uu - uv) - vw * uu * (vv - uv);
    let d1 = uu * nvw - uv * ww * (vv - vw) - wu * vv * (ww - vw);
    let d2 = vv * nwu - vw * uu * (ww - wu) - uv * ww * (uu - wu);
    let mut mask = 0u8;
    for (i, dv, f) in [
        (1usize, d1, [a, c, d, b]),
        (2, d2, [a, d, b, c]),
        (3, d3, [a, b, c, d]),
    ] {
        let s = if ok && dv > eps {
            Sign::Positive
        } else if ok && -dv > eps {
            Sign::Negative
        } else {
            triangle_diametral_side(f[0], f[1], f[2], f[3])
        };
        if s.is_negative() {
            mask |= 1 << i;
        }
    }
    if triangle_diametral_side(b, d, c, a).is_negative() {
        mask |= 1;
    }
    let r2 = radius2_from(p, &f);
    (r2, mask)
}

/// Squared circumradius of the tet `p` from its [`TetFrame`]: shared by
/// [`cell_radius2_and_mask`] and [`tet_radius2`] so that both give the
/// same bits.
#[inline(always)]
fn radius2_from(p: [&Point3; 4], f: &TetFrame) -> f64 {
    let TetFrame {
        u,
        v,
        w,
        uu,
        vv,
        ww,
        cvw,
        cwu,
        cuv,
    } = *f;
    let (u, v, w) = (&u, &v, &w);
    let [a, b, c, d] = p;
    // The circumradius. Relative errors are below ~8ε·p/|x|: keep the
    // float result while that is under ~2e-12 (|x| ≥ 1e-3·p).
    let pc = |x: &Point3, y: &Point3| {
        [
            (x[1] * y[2]).abs() + (x[2] * y[1]).abs(),
            (x[2] * y[0]).abs() + (x[0] * y[2]).abs(),
            (x[0] * y[1]).abs() + (x[1] * y[0]).abs(),
        ]
    };
    let (pvw, pwu, puv) = (pc(v, w), pc(w, u), pc(u, v));
    let det = u[0] * cvw[0] + u[1] * cvw[1] + u[2] * cvw[2];
    let pdet = u[0].abs() * pvw[0] + u[1].abs() * pvw[1] + u[2].abs() * pvw[2];
    let n: [f64; 3] = std::array::from_fn(|k| uu * cvw[k] + vv * cwu[k] + ww * cuv[k]);
    let pn: [f64; 3] = std::array::from_fn(|k| uu * pvw[k] + vv * pwu[k] + ww * puv[k]);
    let nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    let pnn = pn[0] * pn[0] + pn[1] * pn[1] + pn[2] * pn[2];
    if det.abs() >= 1e-3 * pdet && nn >= 1e-6 * pnn && pdet > 0.0 {
        nn / (4.0 * det * det)
    } else {
        tet_radius2_exact(a, b, c, d)
    }
}

/// Squared circumradius of the tet `abcd` (`+∞` if flat), exactly as
/// [`cell_radius2_and_mask`] computes it.
#[inline]
pub(crate) fn tet_radius2(p: [&Point3; 4]) -> f64 {
    radius2_from(p, &TetFrame::new(p))
}

/// The edge vectors `u, v, w` of a tet from its first vertex, their
/// squared lengths and the cross products `v × w, w × u, u × v`: the
/// common start of [`cell_radius2_and_mask`] and [`tet_radius2`].
#[derive(Clone, Copy)]
struct TetFrame {
    u: Point3,
    v: Point3,
    w: Point3,
    uu: f64,
    vv: f64,
    ww: f64,
    cvw: Point3,
    cwu: Point3,
    cuv: Point3,
}

impl TetFrame {
    #[inline(always)]
    fn new(p: [&Point3; 4]) -> TetFrame {
        let [a, b, c, d] = p;
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        let dot = |x: &Point3, y: &Point3| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
        let cr = |x: &Point3, y: &Point3| {
            [
                x[1] * y[2] - x[2] * y[1],
                x[2] * y[0] - x[0] * y[2],
                x[0] * y[1] - x[1] * y[0],
            ]
        };
        TetFrame {
            uu: dot(&u, &u),
            vv: dot(&v, &v),
            ww: dot(&w, &w),
            cvw: cr(&v, &w),
            cwu: cr(&w, &u),
            cuv: cr(&u, &v),
            u,
            v,
            w,
        }
    }
}

#[cold]
#[inline(never)]
fn tet_radius2_exact(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> f64 {
    let u: [Expansion; 3] = std::array::from_fn(|k| Expansion::diff(b[k], a[k]));
    let v: [Expansion; 3] = std::array::from_fn(|k| Expansion::diff(c[k], a[k]));
    let w: [Expansion; 3] = std::array::from_fn(|k| Expansion::diff(d[k], a[k]));
    let dot = |x: &[Expansion; 3], y: &[Expansion; 3]| {
        x[0].mul(&y[0]).add(&x[1].mul(&y[1])).add(&x[2].mul(&y[2]))
    };
    let cross = |x: &[Expansion; 3], y: &[Expansion; 3]| -> [Expansion; 3] {
        std::array::from_fn(|k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            x[i].mul(&y[j]).sub(&x[j].mul(&y[i]))
        })
    };
    let (uu, vv, ww) = (dot(&u, &u), dot(&v, &v), dot(&w, &w));
    let (vw, wu, uv) = (cross(&v, &w), cross(&w, &u), cross(&u, &v));
    let det = dot(&u, &vw).estimate();
    if det == 0.0 {
        return f64::INFINITY;
    }
    let n: [f64; 3] = std::array::from_fn(|k| {
        uu.mul(&vw[k])
            .add(&vv.mul(&wu[k]))
            .add(&ww.mul(&uv[k]))
            .estimate()
    });
    (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / (4.0 * det * det)
}

/// `|u × v|²` for `u = b − a`, `v = c − a`, accurate to a few ulps: the
/// cross product's components are recomputed exactly when cancellation may
/// have cost more than about 10 bits.
#[inline]
pub(crate) fn cross_norm2(a: &Point3, b: &Point3, c: &Point3, u: &Point3, v: &Point3) -> f64 {
    let (n, p) = (cross(*u, *v), cross_permanent(*u, *v));
    let (nn, pp) = (dot(n, n), dot(p, p));
    if nn >= 1e-6 * pp && pp > 0.0 {
        return nn;
    }
    cross_norm2_exact(a, b, c)
}

#[cold]
#[inline(never)]
fn cross_norm2_exact(a: &Point3, b: &Point3, c: &Point3) -> f64 {
    let u: [Expansion; 3] = std::array::from_fn(|k| Expansion::diff(b[k], a[k]));
    let v: [Expansion; 3] = std::array::from_fn(|k| Expansion::diff(c[k], a[k]));
    let n: [f64; 3] = std::array::from_fn(|k| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        u[i].mul(&v[j]).sub(&u[j].mul(&v[i])).estimate()
    });
    n[0] * n[0] + n[1] * n[1] + n[2] * n[2]
}

// ---------------------------------------------------------------------------
// Shewchuk's expansion arithmetic (nonoverlapping, increasing magnitude,
// zero-eliminated). Only used on the rare exact path, so plain `Vec`s.

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    let br = b - bv;
    let ar = a - av;
    (x, ar + br)
}

#[inline]
fn split(a: f64) -> (f64, f64) {
    // 2^27 + 1
    let c = 134_217_729.0 * a;
    let abig = c - a;
    let hi = c - abig;
    (hi, a - hi)
}

#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    let (ahi, alo) = split(a);
    let (bhi, blo) = split(b);
    let err1 = x - ahi * bhi;
    let err2 = err1 - alo * bhi;
    let err3 = err2 - ahi * blo;
    (x, alo * blo - err3)
}

/// An exact sum of `f64` components (Shewchuk's expansions).
#[derive(Clone, Debug)]
pub(crate) struct Expansion(Vec<f64>);

impl Expansion {
    fn zero() -> Self {
        Expansion(Vec::new())
    }

    /// The exact difference `a − b`.
    pub(crate) fn diff(a: f64, b: f64) -> Self {
        let (x, y) = two_sum(a, -b);
        let mut e = Vec::with_capacity(2);
        if y != 0.0 {
            e.push(y);
        }
        if x != 0.0 {
            e.push(x);
        }
        Expansion(e)
    }

    /// Exact sum (Shewchuk's `linear_expansion_sum_zeroelim` by repeated
    /// `grow_expansion`, which is simple and exact).
    pub(crate) fn add(&self, f: &Expansion) -> Expansion {
        let mut h = self.0.clone();
        for &b in &f.0 {
            h = grow(&h, b);
        }
        Expansion(h)
    }

    pub(crate) fn neg(&self) -> Expansion {
        Expansion(self.0.iter().map(|x| -x).collect())
    }

    pub(crate) fn sub(&self, f: &Expansion) -> Expansion {
        self.add(&f.neg())
    }

    /// Exact product.
    pub(crate) fn mul(&self, f: &Expansion) -> Expansion {
        let mut acc = Expansion::zero();
        for &b in &f.0 {
            acc = acc.add(&self.scale(b));
        }
        acc
    }

    /// Exact product by a double (`scale_expansion_zeroelim`).
    fn scale(&self, b: f64) -> Expansion {
        let e = &self.0;
        let mut h = Vec::with_capacity(2 * e.len());
        if e.is_empty() || b == 0.0 {
            return Expansion(h);
        }
        let (mut q, hh) = two_product(e[0], b);
        if hh != 0.0 {
            h.push(hh);
        }
        for &x in &e[1..] {
            let (p1, p0) = two_product(x, b);
            let (sum, hh) = two_sum(q, p0);
            if hh != 0.0 {
                h.push(hh);
            }
            let (nq, hh) = two_sum(p1, sum);
            // p1 + sum is exact as fast_two_sum in Shewchuk; two_sum is safe.
            q = nq;
            if hh != 0.0 {
                h.push(hh);
            }
        }
        if q != 0.0 {
            h.push(q);
        }
        Expansion(h)
    }

    /// Sign of the exact value: that of the most significant component.
    pub(crate) fn sign(&self) -> i32 {
        match self.0.last() {
            None => 0,
            Some(&x) if x > 0.0 => 1,
            Some(_) => -1,
        }
    }

    /// The value rounded to a double (approximately: sum of components
    /// from the smallest up, accurate to a few ulps).
    pub(crate) fn estimate(&self) -> f64 {
        self.0.iter().sum()
    }
}

/// `grow_expansion_zeroelim`: the exact sum of the expansion `e` and `b`.
fn grow(e: &[f64], b: f64) -> Vec<f64> {
    let mut h = Vec::with_capacity(e.len() + 1);
    let mut q = b;
    for &x in e {
        let (s, hh) = two_sum(q, x);
        q = s;
        if hh != 0.0 {
            h.push(hh);
        }
    }
    if q != 0.0 {
        h.push(q);
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expansion_exact_small() {
        // (1 + 2^-60) * (1 - 2^-60) - 1 = -2^-120
        let a = Expansion::zero().add(&Expansion(vec![2f64.powi(-60), 1.0]));
        let b = Expansion::diff(1.0, 2f64.powi(-60));
        let one = Expansion(vec![1.0]);
        let r = a.mul(&b).sub(&one);
        assert_eq!(r.sign(), -1);
        assert_eq!(r.estimate(), -(2f64.powi(-120)));
    }

    /// The shared evaluation in `cell_radius2_and_mask` decides every face
    /// like `triangle_diametral_side`, on random and on grid (tie-rich)
    /// tets.
    #[test]
    fn cell_mask_matches_per_face_tests() {
        use crate::delaunay::FACE;
        let mut rng = crate::rng::SplitMix64::new(7);
        let mut rnd = || rng.uniform();
        let mut set = 0;
        for it in 0..20000 {
            let p: [Point3; 4] = std::array::from_fn(|_| {
                if it % 2 == 0 {
                    [rnd(), rnd(), rnd()]
                } else {
                    [
                        (rnd() * 4.0).floor(),
                        (rnd() * 4.0).floor(),
                        (rnd() * 4.0).floor(),
                    ]
                }
            });
            // positively oriented, non-flat tets only
            if crate::geometry::predicates::orient3d(&p[0], &p[1], &p[2], &p[3]) <= Sign::Zero {
                continue;
            }
            let (_, m) = cell_radius2_and_mask([&p[0], &p[1], &p[2], &p[3]]);
            for (i, f) in FACE.iter().enumerate() {
                let want =
                    triangle_diametral_side(&p[f[0]], &p[f[1]], &p[f[2]], &p[i]).is_negative();
                assert_eq!((m >> i) & 1 == 1, want, "{p:?} face {i}");
                set += want as usize;
            }
        }
        assert!(set > 1000);
    }

    #[test]
    fn ties_are_zero() {
        // Cospherical: a point on the diametral sphere of a skewed triangle
        // with non-representable differences.
        let a = [0.1, 0.2, 0.3];
        let b = [0.1 + 4.0, 0.2, 0.3];
        assert_eq!(edge_exact(&a, &b, &a), 0);
        assert_eq!(edge_diametral_side(&a, &b, &b), Sign::Zero);
        let c = [0.1, 0.2 + 3.0, 0.3];
        assert_eq!(triangle_exact(&a, &b, &c, &a), 0);
        assert_eq!(triangle_diametral_side(&a, &b, &c, &c), Sign::Zero);
    }
}
