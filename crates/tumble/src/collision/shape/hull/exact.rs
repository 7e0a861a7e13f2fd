//! The exact sign of the orientation determinant, after Shewchuk: a floating-point filter
//! settles almost every query and the rest are evaluated exactly with non-overlapping
//! floating-point expansions. Exactness is what keeps the hull's visibility decisions mutually
//! consistent, and so its topology valid, when points are (nearly) coplanar.

use glam::DVec3;

/// Sign (−1, 0, 1) of (b − a) × (c − a) · (p − a): positive when `p` is strictly above
/// the plane of the counter-clockwise triangle (a, b, c). Coordinates must be small enough
/// that products of three differences neither overflow nor underflow.
pub fn side(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> i8 {
    let (ad, bd, cd) = (a - p, b - p, c - p);
    let det = ad.x * (bd.y * cd.z - bd.z * cd.y)
        + bd.x * (cd.y * ad.z - cd.z * ad.y)
        + cd.x * (ad.y * bd.z - ad.z * bd.y);
    let permanent = ((bd.y * cd.z).abs() + (bd.z * cd.y).abs()) * ad.x.abs()
        + ((cd.y * ad.z).abs() + (cd.z * ad.y).abs()) * bd.x.abs()
        + ((ad.y * bd.z).abs() + (ad.z * bd.y).abs()) * cd.x.abs();
    // Shewchuk bounds this evaluation's error by (7 + 56ε)ε·permanent, ε = 2⁻⁵³.
    let bound = 8.0 * f64::EPSILON * permanent;
    // det = (a − p)·((b − p) × (c − p)) is the negated side.
    if det > bound {
        -1
    } else if det < -bound {
        1
    } else {
        -exact_sign(a, b, c, p)
    }
}

/// (b − a) × (c − a) in double-double arithmetic, rounded once at the end. The plain
/// float cross product of a sliver cancels to noise, and its plane, tilted by that noise,
/// would misplace points far away along it; here the error stays near one ulp of the result.
pub fn cross(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let u = [0, 1, 2].map(|i| two_diff_dd(b[i], a[i]));
    let v = [0, 1, 2].map(|i| two_diff_dd(c[i], a[i]));
    let component = |i: usize, j: usize| {
        let (p, q) = (mul_dd(u[i], v[j]), mul_dd(u[j], v[i]));
        let (s, e) = two_sum(p.0, -q.0);
        s + (e + (p.1 - q.1))
    };
    DVec3::new(component(1, 2), component(2, 0), component(0, 1))
}

/// a − b as an unevaluated (high, low) pair.
fn two_diff_dd(a: f64, b: f64) -> (f64, f64) {
    let x = a - b;
    let bv = a - x;
    let av = x + bv;
    (x, (a - av) + (bv - b))
}

/// The product of two (high, low) pairs to about 106 bits (the low·low term is below that).
fn mul_dd(x: (f64, f64), y: (f64, f64)) -> (f64, f64) {
    let (p, e) = two_product(x.0, y.0);
    two_sum(p, e + (x.0 * y.1 + x.1 * y.0))
}

/// Sign of (a − p)·((b − p) × (c − p)), exactly.
fn exact_sign(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> i8 {
    let d = |u: DVec3| [0, 1, 2].map(|i| two_diff(u[i], p[i]));
    let ([adx, ady, adz], [bdx, bdy, bdz], [cdx, cdy, cdz]) = (d(a), d(b), d(c));
    let bc = sub(&mul(&bdy, &cdz), &mul(&bdz, &cdy));
    let ca = sub(&mul(&cdy, &adz), &mul(&cdz, &ady));
    let ab = sub(&mul(&ady, &bdz), &mul(&adz, &bdy));
    let det = add(&add(&mul(&adx, &bc), &mul(&bdx, &ca)), &mul(&cdx, &ab));
    // Components grow in magnitude and do not overlap, so the last one sets the sign.
    match det.last() {
        Some(&x) if x > 0.0 => 1,
        Some(&x) if x < 0.0 => -1,
        _ => 0,
    }
}

/// Expansions: non-overlapping components in increasing magnitude, zeros dropped.
type Expansion = Vec<f64>;

fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

fn two_diff(a: f64, b: f64) -> Expansion {
    let (x, y) = two_diff_dd(a, b);
    [y, x].into_iter().filter(|&c| c != 0.0).collect()
}

/// Veltkamp's split of a double into two 26-bit halves, for exact products without FMA.
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a;
    let hi = c - (c - a);
    (hi, a - hi)
}

fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    let ((ah, al), (bh, bl)) = (split(a), split(b));
    let err = x - ah * bh - al * bh - ah * bl;
    (x, al * bl - err)
}

fn push(h: &mut Expansion, x: f64) {
    if x != 0.0 {
        h.push(x);
    }
}

/// e + b (Shewchuk's Grow-Expansion).
fn grow(e: &[f64], b: f64) -> Expansion {
    let mut h = Vec::with_capacity(e.len() + 1);
    let mut q = b;
    for &ei in e {
        let (s, err) = two_sum(q, ei);
        push(&mut h, err);
        q = s;
    }
    push(&mut h, q);
    h
}

fn add(e: &[f64], f: &[f64]) -> Expansion {
    f.iter().fold(e.to_vec(), |h, &fi| grow(&h, fi))
}

fn sub(e: &[f64], f: &[f64]) -> Expansion {
    let neg: Expansion = f.iter().map(|&x| -x).collect();
    add(e, &neg)
}

/// e·b (Shewchuk's Scale-Expansion).
fn scale(e: &[f64], b: f64) -> Expansion {
    let mut h = Vec::with_capacity(2 * e.len());
    let Some((&e0, rest)) = e.split_first() else {
        return h;
    };
    let (mut q, err) = two_product(e0, b);
    push(&mut h, err);
    for &ei in rest {
        let (p1, p0) = two_product(ei, b);
        let (s, err) = two_sum(q, p0);
        push(&mut h, err);
        let (s2, err2) = two_sum(p1, s);
        push(&mut h, err2);
        q = s2;
    }
    push(&mut h, q);
    h
}

fn mul(e: &[f64], f: &[f64]) -> Expansion {
    f.iter().fold(Vec::new(), |h, &fi| add(&h, &scale(e, fi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_sign_is_zero_for_exactly_coplanar_points_where_floats_lose_it() {
        // The plane z = x/4 + y/8 far from the origin; every coordinate is exact.
        let on = |x: f64, y: f64| DVec3::new(x, y, x / 4.0 + y / 8.0);
        let big = 2f64.powi(40);
        let (a, b, c) = (on(big, 3.0), on(big + 1.0, big), on(7.0, big + 5.0));
        let p = on(big * 0.5 + 0.25, big * 0.75 + 0.5);
        assert_eq!(side(a, b, c, p), 0);
        let up = p + DVec3::new(0.0, 0.0, 2f64.powi(-10));
        assert_eq!(side(a, b, c, up), 1);
        assert_eq!(side(a, c, b, up), -1);
    }

    #[test]
    fn near_coplanar_signs_are_consistent_under_permutation() {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let mut pt = || {
                let (x, y) = (rnd() * 10.0 - 5.0, rnd() * 10.0 - 5.0);
                DVec3::new(x, y, 0.3 * x - 0.7 * y + 0.1)
            };
            let (a, b, c, p) = (pt(), pt(), pt(), pt());
            let s0 = side(a, b, c, p);
            assert_eq!(s0, side(b, c, a, p));
            assert_eq!(s0, side(c, a, b, p));
            assert_eq!(s0, -side(b, a, c, p));
            // Swapping the query point with a vertex flips the sign of the determinant.
            assert_eq!(s0, -side(p, b, c, a));
        }
    }

    #[test]
    fn sliver_cross_products_match_exact_arithmetic() {
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for k in 0..2000 {
            let a = DVec3::new(rnd(), rnd(), rnd()) * 7.0;
            let b = DVec3::new(rnd(), rnd(), rnd()) * 7.0;
            // Within about 1e-15 .. 1e-3 of the line ab: the float cross product of the
            // thinnest of these has no correct digit.
            let off = DVec3::new(rnd(), rnd(), rnd()) * 10f64.powi(-3 - k % 13);
            let c = a + (b - a) * rnd() + off;
            let d = |u: f64, v: f64| two_diff(u, v);
            let (u, v) = (
                [0, 1, 2].map(|i| d(b[i], a[i])),
                [0, 1, 2].map(|i| d(c[i], a[i])),
            );
            let exact = |i: usize, j: usize| -> f64 {
                sub(&mul(&u[i], &v[j]), &mul(&u[j], &v[i])).iter().sum()
            };
            let expect = DVec3::new(exact(1, 2), exact(2, 0), exact(0, 1));
            let got = cross(a, b, c);
            assert!((got - expect).length() <= 4.0 * f64::EPSILON * expect.length());
        }
    }
}
