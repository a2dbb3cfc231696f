//! Rotations: 3x3 matrices, unit quaternions and Euler angles, in `f32` (the device) or `f64`
//! (the host tools), one implementation for both through the [`Real`] trait.
//!
//! ## Conventions
//!
//! - Angles are in **degrees** at the API (BVH channels and rig channels are degrees);
//!   radians inside.
//! - Matrices are row-major (`m[row][col]`) and act on column vectors; rotations are
//!   right-handed. [`axis_rotation`]`(0, a)` is `Rx(a)`.
//! - A BVH joint's local rotation is the product of its axis rotations in the order its
//!   `CHANNELS` line lists them: `Zrotation Yrotation Xrotation` is `Rz(z) * Ry(y) * Rx(x)`
//!   ([`euler_matrix`] with order `[2, 1, 0]`).
//! - Quaternions are `[w, x, y, z]`, unit length, with `w >= 0` where this module chooses the
//!   sign ([`quaternion`]).
//! - [`euler_angles`] is the inverse of [`euler_matrix`]: for `m = R_o0(a) R_o1(b) R_o2(c)` it
//!   returns `[a, b, c]` with `a, c` in `[-180, 180]`, `b` in `[-90, 90]`; at gimbal lock
//!   (`|b| = 90`) only `a +- c` is defined and it is all put in `a` (`c = 0`).
//!
//! ## Invariants
//!
//! Nothing here allocates or panics, for any input (axis indices are clamped to 0..=2; a
//! degenerate quaternion becomes the identity). Finite input gives finite output. `f32` and
//! `f64` results differ only by rounding: the same code runs in both.

use core::ops::{Add, Div, Mul, Neg, Sub};

/// The floating-point operations the rotation code needs (implemented for `f32` and `f64`
/// with `libm`, so the device and the host compute the same way).
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// The nearest value to `v`.
    fn of(v: f64) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Sine (radians).
    fn sin(self) -> Self;
    /// Cosine (radians).
    fn cos(self) -> Self;
    /// `atan2(self, x)`.
    fn atan2(self, x: Self) -> Self;
    /// Arc sine.
    fn asin(self) -> Self;
    /// Arc cosine.
    fn acos(self) -> Self;
    /// Largest whole number not above the value.
    fn floor(self) -> Self;
    /// Whether the value is neither infinite nor NaN.
    fn finite(self) -> bool;
    /// Absolute value.
    fn abs(self) -> Self {
        if self < Self::ZERO {
            -self
        } else {
            self
        }
    }
    /// `self` clamped into `[lo, hi]` (NaN stays NaN).
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        if self < lo {
            lo
        } else if self > hi {
            hi
        } else {
            self
        }
    }
    /// Degrees to radians.
    fn to_rad(self) -> Self {
        self * Self::of(core::f64::consts::PI / 180.0)
    }
    /// Radians to degrees.
    fn to_deg(self) -> Self {
        self * Self::of(180.0 / core::f64::consts::PI)
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    fn of(v: f64) -> Self {
        v as f32
    }
    fn sqrt(self) -> Self {
        libm::sqrtf(self)
    }
    fn sin(self) -> Self {
        sin_cos_f32(self).0
    }
    fn cos(self) -> Self {
        sin_cos_f32(self).1
    }
    fn atan2(self, x: Self) -> Self {
        libm::atan2f(self, x)
    }
    fn asin(self) -> Self {
        // As `atan2`, not `libm::asinf`: that one works in `f64` inside and links the
        // software double routines on a single-precision FPU.
        libm::atan2f(self, libm::sqrtf((1.0 - self) * (1.0 + self)))
    }
    fn acos(self) -> Self {
        libm::acosf(self)
    }
    fn floor(self) -> Self {
        libm::floorf(self)
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// `(sin x, cos x)` in `f32`: the argument reduced to `[-pi/4, pi/4]` by quarter turns
/// (Cody-Waite, three constants), then Taylor kernels to the 9th and 8th power (within 5e-7 of
/// `libm` up to 4096 radians; beyond, the angle is first folded into one turn with `f32`'s 2 pi,
/// which is finite but not exact). Written here because `libm::sinf`/`cosf` bring their
/// large-argument reduction, about 4 KiB of code on a Cortex-M4, for angles that are degrees of
/// a joint. Not finite in, NaN out (as `libm`).
pub fn sin_cos_f32(x: f32) -> (f32, f32) {
    if !x.is_finite() {
        return (f32::NAN, f32::NAN);
    }
    // pi/2 in three parts with few mantissa bits each, so q * part is exact for |q| < 2^12.
    const PIO2_1: f32 = 1.570_312_5;
    const PIO2_2: f32 = 4.837_513e-4;
    const PIO2_3: f32 = 7.549_79e-8;
    // Far from zero (no joint angle is), fold into one turn first: finite, if not exact.
    let x = if x.abs() > 4096.0 {
        libm::fmodf(x, core::f32::consts::TAU)
    } else {
        x
    };
    let q = libm::roundf(x * core::f32::consts::FRAC_2_PI);
    let r = ((x - q * PIO2_1) - q * PIO2_2) - q * PIO2_3;
    let r2 = r * r;
    let s =
        r * (1.0 + r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0 + r2 / 362_880.0))));
    let c = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 / 40_320.0)));
    // The quadrant, from the low bits of q (q may be huge; only q mod 4 matters).
    let quadrant = libm::fmodf(q, 4.0);
    let quadrant = if quadrant < 0.0 {
        quadrant + 4.0
    } else {
        quadrant
    } as u32;
    match quadrant {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    fn of(v: f64) -> Self {
        v
    }
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    fn sin(self) -> Self {
        libm::sin(self)
    }
    fn cos(self) -> Self {
        libm::cos(self)
    }
    fn atan2(self, x: Self) -> Self {
        libm::atan2(self, x)
    }
    fn asin(self) -> Self {
        libm::asin(self)
    }
    fn acos(self) -> Self {
        libm::acos(self)
    }
    fn floor(self) -> Self {
        libm::floor(self)
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// A 3-vector.
pub type Vec3<T = f64> = [T; 3];
/// A 3x3 matrix, row-major, acting on column vectors.
pub type Mat3<T = f64> = [[T; 3]; 3];
/// A quaternion `[w, x, y, z]`.
pub type Quat<T = f64> = [T; 4];

/// The identity matrix.
pub fn identity<T: Real>() -> Mat3<T> {
    let (o, z) = (T::ONE, T::ZERO);
    [[o, z, z], [z, o, z], [z, z, o]]
}

/// The identity quaternion.
pub fn quat_identity<T: Real>() -> Quat<T> {
    [T::ONE, T::ZERO, T::ZERO, T::ZERO]
}

/// Rotation by `degrees` about axis 0 (X), 1 (Y) or 2 (Z) (larger indices count as Z).
pub fn axis_rotation<T: Real>(axis: usize, degrees: T) -> Mat3<T> {
    let r = degrees.to_rad();
    let (s, c) = (r.sin(), r.cos());
    let (o, z) = (T::ONE, T::ZERO);
    match axis {
        0 => [[o, z, z], [z, c, -s], [z, s, c]],
        1 => [[c, z, s], [z, o, z], [-s, z, c]],
        _ => [[c, -s, z], [s, c, z], [z, z, o]],
    }
}

/// `a * b`.
pub fn mat_mul<T: Real>(a: &Mat3<T>, b: &Mat3<T>) -> Mat3<T> {
    let mut m = [[T::ZERO; 3]; 3];
    for (r, row) in m.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
        }
    }
    m
}

/// `m * v`.
pub fn mat_vec<T: Real>(m: &Mat3<T>, v: &Vec3<T>) -> Vec3<T> {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// The transpose (for a rotation, its inverse).
pub fn transpose<T: Real>(m: &Mat3<T>) -> Mat3<T> {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

/// `R_o0(angles[0]) * R_o1(angles[1]) * R_o2(angles[2])` (degrees).
pub fn euler_matrix<T: Real>(order: [usize; 3], angles: [T; 3]) -> Mat3<T> {
    let a = axis_rotation(order[0], angles[0]);
    let b = axis_rotation(order[1], angles[1]);
    let c = axis_rotation(order[2], angles[2]);
    mat_mul(&mat_mul(&a, &b), &c)
}

/// The unit quaternion of a rotation matrix, `w >= 0` (Shepperd's method: the largest of the
/// four squared components is taken from the diagonal, so there is no division by a small
/// number). A matrix that gives no finite quaternion gives the identity.
pub fn quaternion<T: Real>(m: &Mat3<T>) -> Quat<T> {
    let (one, two, quarter) = (T::ONE, T::of(2.0), T::of(0.25));
    let pos = |v: T| if v > T::ZERO { v } else { T::ZERO };
    let tr = m[0][0] + m[1][1] + m[2][2];
    let q = if tr >= m[0][0] && tr >= m[1][1] && tr >= m[2][2] {
        let s = pos(one + tr).sqrt() * two;
        [
            quarter * s,
            (m[2][1] - m[1][2]) / s,
            (m[0][2] - m[2][0]) / s,
            (m[1][0] - m[0][1]) / s,
        ]
    } else if m[0][0] >= m[1][1] && m[0][0] >= m[2][2] {
        let s = pos(one + m[0][0] - m[1][1] - m[2][2]).sqrt() * two;
        [
            (m[2][1] - m[1][2]) / s,
            quarter * s,
            (m[0][1] + m[1][0]) / s,
            (m[0][2] + m[2][0]) / s,
        ]
    } else if m[1][1] >= m[2][2] {
        let s = pos(one + m[1][1] - m[0][0] - m[2][2]).sqrt() * two;
        [
            (m[0][2] - m[2][0]) / s,
            (m[0][1] + m[1][0]) / s,
            quarter * s,
            (m[1][2] + m[2][1]) / s,
        ]
    } else {
        let s = pos(one + m[2][2] - m[0][0] - m[1][1]).sqrt() * two;
        [
            (m[1][0] - m[0][1]) / s,
            (m[0][2] + m[2][0]) / s,
            (m[1][2] + m[2][1]) / s,
            quarter * s,
        ]
    };
    let q = normalize(q);
    if q[0] < T::ZERO {
        q.map(|v| -v)
    } else {
        q
    }
}

/// `q / |q|`; the identity if that is not finite or `q` is zero.
pub fn normalize<T: Real>(q: Quat<T>) -> Quat<T> {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if !(n.finite() && n > T::ZERO) {
        return quat_identity();
    }
    let r = q.map(|v| v / n);
    if r.iter().all(|v| v.finite()) {
        r
    } else {
        quat_identity()
    }
}

/// The rotation matrix of a unit quaternion.
pub fn quat_matrix<T: Real>(q: &Quat<T>) -> Mat3<T> {
    let [w, x, y, z] = *q;
    let (one, two) = (T::ONE, T::of(2.0));
    [
        [
            one - two * (y * y + z * z),
            two * (x * y - w * z),
            two * (x * z + w * y),
        ],
        [
            two * (x * y + w * z),
            one - two * (x * x + z * z),
            two * (y * z - w * x),
        ],
        [
            two * (x * z - w * y),
            two * (y * z + w * x),
            one - two * (x * x + y * y),
        ],
    ]
}

/// The Hamilton product `a * b` (rotate by `b`, then by `a`).
pub fn quat_mul<T: Real>(a: &Quat<T>, b: &Quat<T>) -> Quat<T> {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The conjugate (the inverse of a unit quaternion).
pub fn quat_conj<T: Real>(q: &Quat<T>) -> Quat<T> {
    [q[0], -q[1], -q[2], -q[3]]
}

/// The rotation vector (axis times angle, radians) of a unit quaternion, taking the shorter
/// way round (`q` and `-q` give the same vector).
pub fn quat_log<T: Real>(q: &Quat<T>) -> Vec3<T> {
    let q = if q[0] < T::ZERO { q.map(|v| -v) } else { *q };
    let s = (q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if s.partial_cmp(&T::of(1e-12)) != Some(core::cmp::Ordering::Greater) {
        // Small angle: log(q) ~ v, to first order (2x for the full angle).
        let two = T::of(2.0);
        return [two * q[1], two * q[2], two * q[3]];
    }
    let angle = T::of(2.0) * s.atan2(q[0]);
    let k = angle / s;
    [k * q[1], k * q[2], k * q[3]]
}

/// The unit quaternion of a rotation vector (axis times angle, radians): the inverse of
/// [`quat_log`].
pub fn quat_exp<T: Real>(v: &Vec3<T>) -> Quat<T> {
    let angle = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if angle.partial_cmp(&T::of(1e-12)) != Some(core::cmp::Ordering::Greater) {
        let h = T::of(0.5);
        return normalize([T::ONE, h * v[0], h * v[1], h * v[2]]);
    }
    let half = angle * T::of(0.5);
    let k = half.sin() / angle;
    normalize([half.cos(), k * v[0], k * v[1], k * v[2]])
}

/// The angle of axis `axis` (0..=2) in the decomposition of `m` in Euler `order` (degrees; see
/// the module docs).
pub fn euler_angles<T: Real>(m: &Mat3<T>, order: [usize; 3]) -> [T; 3] {
    let [i, j, k] = order.map(|o| o.min(2));
    if i == j || j == k || i == k {
        return [T::ZERO; 3];
    }
    // +1 for cyclic orders (XYZ, YZX, ZXY), -1 for the others.
    let s = if j == (i + 1) % 3 { T::ONE } else { -T::ONE };
    let sb = (s * m[i][k]).clamp_to(-T::ONE, T::ONE);
    let b = sb.asin();
    if T::ONE - sb.abs() > T::of(1e-12) {
        let a = (-s * m[j][k]).atan2(m[k][k]);
        let c = (-s * m[i][j]).atan2(m[i][i]);
        [a.to_deg(), b.to_deg(), c.to_deg()]
    } else {
        // Gimbal lock: only a + c (or a - c) is defined; put it all in `a`. What is left after
        // undoing the middle rotation is a rotation about axis i.
        let b_deg = b.to_deg();
        let rest = mat_mul(m, &transpose(&axis_rotation(j, b_deg)));
        let (p, q) = ((i + 1) % 3, (i + 2) % 3);
        let a = rest[q][p].atan2(rest[p][p]);
        [a.to_deg(), b_deg, T::ZERO]
    }
}

/// The twist angle (degrees, `[-180, 180]`) of rotation `m` about axis `axis` (0..=2): for its
/// quaternion `(w, v)` with `w >= 0`, `2 atan2(v[axis], w)` (swing-twist decomposition).
pub fn twist_deg<T: Real>(m: &Mat3<T>, axis: usize) -> T {
    let q = quaternion(m);
    (T::of(2.0) * q[1 + axis.min(2)].atan2(q[0])).to_deg()
}

/// `deg` wrapped into `[-180, 180]`.
pub fn wrap_deg<T: Real>(deg: T) -> T {
    if !deg.finite() {
        return deg;
    }
    let full = T::of(360.0);
    let half = T::of(180.0);
    // deg - 360 * floor((deg + 180) / 360), clamped against rounding at the ends.
    let x = (deg + half) / full;
    let fl = x.floor();
    (deg - full * fl).clamp_to(-half, half)
}

#[cfg(test)]
mod tests {
    #[test]
    fn sin_cos_f32_agrees_with_libm() {
        let mut worst = 0.0f32;
        for i in 0..200_000 {
            let x = -50.0 + i as f32 * 0.0005;
            let (s, c) = super::sin_cos_f32(x);
            worst = worst
                .max((s - libm::sinf(x)).abs())
                .max((c - libm::cosf(x)).abs());
        }
        assert!(worst < 5e-7, "{worst}");
        // Up to 4096 radians (about 235 000 degrees), sampled more sparsely.
        let mut far = 0.0f32;
        for i in 0..200_000 {
            let x = -4096.0 + i as f32 * 0.04096;
            let (s, c) = super::sin_cos_f32(x);
            far = far
                .max((s - libm::sinf(x)).abs())
                .max((c - libm::cosf(x)).abs());
        }
        assert!(far < 1e-6, "{far}");
        let (s, c) = super::sin_cos_f32(1.0e30);
        assert!(s.is_finite() && c.is_finite() && s.abs() <= 1.01 && c.abs() <= 1.01);
        assert!(super::sin_cos_f32(f32::NAN).0.is_nan());
    }

    use super::*;

    fn close(a: &Mat3<f64>, b: &Mat3<f64>, tol: f64) -> bool {
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn axis_rotations_are_right_handed() {
        // Rz(90) takes X to Y.
        let v = mat_vec(&axis_rotation(2, 90.0), &[1.0, 0.0, 0.0]);
        assert!((v[0]).abs() < 1e-12 && (v[1] - 1.0).abs() < 1e-12);
        // Rx(90) takes Y to Z; Ry(90) takes Z to X.
        let v = mat_vec(&axis_rotation(0, 90.0), &[0.0, 1.0, 0.0]);
        assert!((v[2] - 1.0).abs() < 1e-12);
        let v = mat_vec(&axis_rotation(1, 90.0), &[0.0, 0.0, 1.0]);
        assert!((v[0] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn euler_angles_invert_euler_matrix_in_every_order() {
        let orders = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        for order in orders {
            for &(a, b, c) in &[
                (10.0, 20.0, 30.0),
                (-170.0, 80.0, 45.0),
                (135.0, -60.0, -100.0),
            ] {
                let m = euler_matrix(order, [a, b, c]);
                let got = euler_angles(&m, order);
                assert!(
                    (got[0] - a).abs() < 1e-9
                        && (got[1] - b).abs() < 1e-9
                        && (got[2] - c).abs() < 1e-9,
                    "{order:?}: {got:?} vs {a} {b} {c}"
                );
                // Gimbal lock: the matrix is reproduced even though the angles are not.
                let m = euler_matrix(order, [a, 90.0, c]);
                let back = euler_matrix(order, euler_angles(&m, order));
                assert!(close(&m, &back, 1e-9), "{order:?} at lock");
            }
        }
    }

    #[test]
    fn quaternion_round_trips_and_agrees_between_f32_and_f64() {
        for &(a, b, c) in &[(10.0, 20.0, 30.0), (179.0, -89.0, 5.0), (0.0, 0.0, 180.0)] {
            let m = euler_matrix([2, 1, 0], [a, b, c]);
            let q = quaternion(&m);
            assert!(q[0] >= 0.0);
            assert!(close(&quat_matrix(&q), &m, 1e-12));
            let m32 = euler_matrix([2, 1, 0], [a as f32, b as f32, c as f32]);
            let q32 = quaternion(&m32);
            // Same rotation up to the sign of a quaternion with w ~ 0 (a half turn).
            let d = |s: f64| (0..4).all(|k| (q32[k] as f64 - s * q[k]).abs() < 1e-5);
            assert!(d(1.0) || d(-1.0), "{q32:?} vs {q:?}");
        }
    }

    #[test]
    fn log_and_exp_are_inverse_and_take_the_short_way() {
        let q = quaternion(&euler_matrix([0, 1, 2], [30.0, -40.0, 50.0]));
        let v = quat_log(&q);
        let back = quat_exp(&v);
        for k in 0..4 {
            assert!((back[k] - q[k]).abs() < 1e-12);
        }
        // -q is the same rotation: same log.
        let v2 = quat_log(&q.map(|x: f64| -x));
        for k in 0..3 {
            assert!((v[k] - v2[k]).abs() < 1e-12);
        }
        // A 90-degree rotation about Z has log (0, 0, pi/2).
        let v = quat_log(&quaternion(&axis_rotation(2, 90.0)));
        assert!((v[2] - core::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // Products: log(a * conj(a)) = 0.
        let z = quat_log(&quat_mul(&q, &quat_conj(&q)));
        assert!(z.iter().all(|x| x.abs() < 1e-12));
    }

    #[test]
    fn twist_of_a_pure_axis_rotation_is_its_angle() {
        for axis in 0..3 {
            for deg in [-170.0, -45.0, 0.0, 30.0, 179.0] {
                let t = twist_deg(&axis_rotation(axis, deg), axis);
                assert!((t - deg).abs() < 1e-9, "axis {axis}: {t} vs {deg}");
            }
        }
    }

    #[test]
    fn wrap_deg_maps_into_half_open_circle() {
        for (x, want) in [
            (190.0, -170.0),
            (-190.0, 170.0),
            (720.0, 0.0),
            (45.0, 45.0),
            (-180.0, -180.0),
        ] {
            assert!((wrap_deg(x) - want).abs() < 1e-9, "{x}: {}", wrap_deg(x));
            assert!((wrap_deg(x as f32) - want as f32).abs() < 1e-4);
        }
    }

    #[test]
    fn garbage_never_panics_and_degenerate_quaternions_are_identity() {
        let m = [[f64::NAN; 3]; 3];
        let q = quaternion(&m);
        assert_eq!(q, [1.0, 0.0, 0.0, 0.0]);
        let _ = euler_angles(&m, [2, 1, 0]);
        let _ = quat_exp(&[f64::INFINITY, 0.0, 0.0]);
        assert_eq!(normalize([0.0f32; 4]), [1.0, 0.0, 0.0, 0.0]);
    }
}
