//! The baseline that engineers use today: Hamrock & Brewe's (1983) closed-form
//! approximation of the Hertz ellipse, evaluated in f32 with libm, then eq (15) for
//! d/b, eq (21) for F and eq (30) iterated for phi0. Benchmark code only: not part of
//! the library. Its ellipticity k = 1.0339 (Ry/Rx)^0.636 was fitted for 1 <= k <= 10;
//! at small misalignment the contact is far more slender (k in the thousands), where it
//! is far off.

/// A scene prepared for the baseline (f32).
#[derive(Clone, Copy, Debug)]
pub struct HamrockBrewe {
    /// Curvature sum 1/R1 + 1/R2 (1/m).
    curvature_sum: f32,
    r1: f32,
    r2: f32,
    /// E' = 2 G / (1 - nu) for one material (Pa).
    e_prime: f32,
    g_modulus: f32,
    friction: f32,
}

/// What the baseline estimates per sample.
#[derive(Clone, Copy, Debug)]
pub struct Baseline {
    /// Slip ratio d/b.
    pub slip_ratio: f32,
    /// Gross slip (d/b >= 1).
    pub gross: bool,
    /// Axial force F (N).
    pub axial_force: f32,
    /// Critical angle phi0 (rad).
    pub critical_angle: f32,
}

impl HamrockBrewe {
    /// The baseline for `scene`.
    pub fn of(scene: &misalign::Scene) -> Self {
        Self::new(
            scene.r1(),
            scene.r2(),
            scene.shear_modulus(),
            scene.poisson_ratio(),
            scene.friction(),
        )
    }

    /// The baseline for radii `r1`, `r2` (m), shear modulus `g` (Pa), Poisson's ratio
    /// `nu` and friction `mu`.
    pub fn new(r1: f64, r2: f64, g: f64, nu: f64, mu: f64) -> Self {
        HamrockBrewe {
            curvature_sum: (1.0 / r1 + 1.0 / r2) as f32,
            r1: r1 as f32,
            r2: r2 as f32,
            e_prime: (2.0 * g / (1.0 - nu)) as f32,
            g_modulus: g as f32,
            friction: mu as f32,
        }
    }

    /// Semi-axes (a along the rollers, b across) for load P and angle phi between the
    /// axes: principal relative curvatures of crossed cylinders (Hertz), then
    /// k = 1.0339 (Ry/Rx)^0.636, E = 1.0003 + 0.5968 Rx/Ry (Hamrock & Brewe 1983).
    pub fn semi_axes(&self, load: f32, phi: f32) -> (f32, f32) {
        let (k1, k2) = (1.0 / self.r1, 1.0 / self.r2);
        let sum = 0.5 * self.curvature_sum; // A + B
        let diff = 0.5 * libm::sqrtf(k1 * k1 + k2 * k2 + 2.0 * k1 * k2 * libm::cosf(2.0 * phi)); // B - A
        // A = sum - diff cancels in f32 at small phi (cos 2phi rounds to 1); a careful
        // engineer uses A B = sum^2 - diff^2 = k1 k2 sin^2(phi) instead.
        let b_curv = sum + diff;
        let sin = libm::sinf(phi);
        let a_curv = k1 * k2 * sin * sin / b_curv; // A <= B
        let ratio = b_curv / a_curv; // Ry / Rx > 1 (Rx = 1/(2B) across, Ry = 1/(2A) along)
        let k = 1.0339 * libm::powf(ratio, 0.6360);
        let e = 1.0003 + 0.5968 / ratio;
        let r = 1.0 / (2.0 * sum); // 1/R = 1/Rx + 1/Ry = 2 (A + B)
        let common = 6.0 * e * load * r / (core::f32::consts::PI * self.e_prime);
        let a = libm::cbrtf(common * k * k);
        let b = libm::cbrtf(common / k);
        (a, b)
    }

    /// The baseline's estimate for load `load` (N) and misalignment `phi` (rad).
    pub fn estimate(&self, load: f32, phi: f32) -> Baseline {
        let abs_phi = libm::fabsf(phi);
        let (a, b) = self.semi_axes(load, abs_phi);
        let pi = core::f32::consts::PI;
        let s = pi * self.g_modulus * a * b * abs_phi / (3.0 * self.friction * load); // eq (15)
        let ratio = if s >= 1.0 {
            1.0
        } else {
            let root = libm::sqrtf(1.0 - s * s);
            1.0 - (1.0 + 0.5 * s * s) * root + 1.5 * s * libm::acosf(s) // eq (21)
        };
        // phi0 = 2 mu p0(phi0) / G (eq 30), p0 = 3P / (2 pi a b), iterated from phi.
        let mut phi0 = abs_phi.max(1e-6);
        for _ in 0..6 {
            let (a0, b0) = self.semi_axes(load, phi0);
            phi0 = 2.0 * self.friction * 3.0 * load / (2.0 * pi * a0 * b0) / self.g_modulus;
        }
        Baseline {
            slip_ratio: s,
            gross: s >= 1.0,
            axial_force: libm::copysignf(self.friction * load * ratio, phi),
            critical_angle: phi0,
        }
    }
}
