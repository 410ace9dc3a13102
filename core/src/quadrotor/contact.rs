//! Ground contact on four landing-gear feet.
//!
//! The feet sit at body (±gear_x, ±gear_y, gear_z), in the order of the rotors above them
//! (PX4 quad-X: front-right, rear-left, front-left, rear-right). A foot that is δ below the
//! ground plane z = 0 pushes up with N = max(0, k·δ − c·v_z): a spring-damper that never
//! pulls. Along the ground it rubs with Coulomb friction of at most μ·N.
//!
//! Friction is a bristle (elasto-plastic) model, because a friction force that is a function
//! of the velocity alone (regularised Coulomb) lets any sideways push below μ·N creep the
//! vehicle along at a small speed. Each foot carries a 2D stretch s in the state. While
//! |k·s + c·v_t| ≤ μ·N the foot sticks: the bristle stretches with the foot (ṡ = v_t) and
//! pushes back with F = −(k·s + c·v_t), so a constant sideways push deflects the vehicle by
//! F/4k and it stays there. Beyond that the foot slips with |F| = μ·N and the bristle relaxes
//! to μ·N/k (ṡ = (−F − k·s)/c, which equals v_t on the boundary, so the rates are continuous).
//! A foot off the ground has N = 0, hence F = 0 and a bristle relaxing with time constant
//! c/k; the integrator sets it to exactly zero at the end of a substep that ends with the foot
//! above the ground (the lift-off event of a Model-Exchange solver). Everything here is a pure
//! function of the state: [`foot_heights`] are the event indicators.
//!
//! Energy: with E = kinetic + m·g·z + Σ ½k·δ² + Σ ½k·|s|² ([`gear_energy`] is the last two),
//! each part of the contact only removes energy (the dampers, the clamp N ≥ 0 when the spring
//! would pull, slipping), so a dropped vehicle bounces lower each time and comes to rest.
//!
//! Stiffness and step: the default k = 3000 N/m per foot gives a vertical bounce at
//! ω = √(4k/m) = 110 rad/s for 1 kg (89 rad/s for 1.5 kg); tilt and yaw modes are slower.
//! RK4 is stable up to ω·h ≈ 2.8 and loses well under 1 % of the energy per bounce at
//! ω·h ≈ 0.2, so a step in which a foot may touch uses substeps of at most `contact_substep`
//! (2 ms: ω·h = 0.22): 5 substeps for a 10 ms control step, 2 for PX4's 4 ms step. A step in
//! which no foot can reach the ground keeps `max_substep` and never evaluates the contact.

use super::dynamics::BRISTLES;
use super::params::QuadrotorParams;
use super::state::BodyState;

/// Signs (forward, left) of the four feet: front-right, rear-left, front-left, rear-right
/// (the quad X's rotor order, whatever the frame).
const FOOT_SIGNS: [(f64, f64); 4] = [(1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (-1.0, -1.0)];

/// The four feet in body FLU, m.
pub fn feet(p: &QuadrotorParams) -> [[f64; 3]; 4] {
    FOOT_SIGNS.map(|(fwd, left)| [fwd * p.gear_x, left * p.gear_y, p.gear_z])
}

/// Distance of every foot from the centre of mass, m: while z exceeds it no foot can be on
/// the ground, whatever the attitude.
pub fn gear_reach(p: &QuadrotorParams) -> f64 {
    (p.gear_x * p.gear_x + p.gear_y * p.gear_y + p.gear_z * p.gear_z).sqrt()
}

/// Height of each foot above the ground plane, m, in rotor order; negative while it presses
/// into the ground. These are the natural event indicators of the contact.
pub fn foot_heights(p: &QuadrotorParams, body: &BodyState) -> [f64; 4] {
    let q = &body.attitude;
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    // Third row of the rotation body → world: the world z of a body vector.
    let row = [
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    ];
    feet(p).map(|f| body.position.z + row[0] * f[0] + row[1] * f[1] + row[2] * f[2])
}

/// Height of the centre of mass when the vehicle rests level on its four feet, each carrying
/// m·g/4, m.
pub fn rest_height(p: &QuadrotorParams) -> f64 {
    -p.gear_z - p.mass * p.gravity / (4.0 * p.gear_stiffness)
}

/// Energy stored in the gear: Σ ½k·δ² over the feet in the ground plus Σ ½k·|s|² over the
/// bristles, J.
pub fn gear_energy(p: &QuadrotorParams, body: &BodyState) -> f64 {
    let springs: f64 = foot_heights(p, body)
        .iter()
        .map(|h| h.min(0.0) * h.min(0.0))
        .sum();
    let bristles: f64 = body
        .gear_stretch
        .iter()
        .map(|s| s[0] * s[0] + s[1] * s[1])
        .sum();
    0.5 * p.gear_stiffness * (springs + bristles)
}

/// The contact's constants, computed once per step that may touch.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Gear {
    feet: [[f64; 3]; 4],
    reach: f64,
    stiffness: f64,
    damping: f64,
    friction: f64,
    /// −k/c: relaxation rate of a bristle off the ground, 1/s.
    relax: f64,
    inv_mass: f64,
    inv_inertia: [f64; 3],
}

impl Gear {
    pub(crate) fn new(p: &QuadrotorParams) -> Self {
        Gear {
            feet: feet(p),
            reach: gear_reach(p),
            stiffness: p.gear_stiffness,
            damping: p.gear_damping,
            friction: p.gear_friction,
            relax: -p.gear_stiffness / p.gear_damping,
            inv_mass: 1.0 / p.mass,
            inv_inertia: [1.0 / p.inertia_xx, 1.0 / p.inertia_yy, 1.0 / p.inertia_zz],
        }
    }

    /// Adds the contact's accelerations to the body rates in `d` and writes the bristle rates
    /// into its last 8 values, for the flat state `x` (layout of the integrator: the rigid
    /// body first, the bristles last; `dynamics`).
    #[inline(always)]
    pub(crate) fn add_rates<const C: usize>(&self, x: &[f64; C], d: &mut [f64; C]) {
        let stretch = C - BRISTLES;
        for i in stretch..C {
            d[i] = self.relax * x[i];
        }
        let z = x[2];
        if z >= self.reach {
            return;
        }
        let (v, w) = ([x[3], x[4], x[5]], [x[10], x[11], x[12]]);
        let r = rotation(x[6], x[7], x[8], x[9]);
        let (k, c) = (self.stiffness, self.damping);
        let mut force = [0.0; 3];
        let mut torque = [0.0; 3];
        for (i, foot) in self.feet.iter().enumerate() {
            let height = z + dot(&r[2], foot);
            if height >= 0.0 {
                continue;
            }
            // Velocity of the foot in the world: v + R (ω × r).
            let spin = cross(&w, foot);
            let vf = [
                v[0] + dot(&r[0], &spin),
                v[1] + dot(&r[1], &spin),
                v[2] + dot(&r[2], &spin),
            ];
            let normal = (k * -height - c * vf[2]).max(0.0);
            let (sx, sy) = (x[stretch + 2 * i], x[stretch + 2 * i + 1]);
            let (tx, ty) = (-(k * sx + c * vf[0]), -(k * sy + c * vf[1]));
            let limit = self.friction * normal;
            let magnitude2 = tx * tx + ty * ty;
            let (fx, fy) = if magnitude2 <= limit * limit {
                d[stretch + 2 * i] = vf[0];
                d[stretch + 2 * i + 1] = vf[1];
                (tx, ty)
            } else {
                let scale = limit / magnitude2.sqrt();
                let (fx, fy) = (tx * scale, ty * scale);
                d[stretch + 2 * i] = (-fx - k * sx) / c;
                d[stretch + 2 * i + 1] = (-fy - k * sy) / c;
                (fx, fy)
            };
            let f = [fx, fy, normal];
            for (total, part) in force.iter_mut().zip(f) {
                *total += part;
            }
            // Torque in the body: r × (Rᵀ F).
            let body_force = [
                r[0][0] * f[0] + r[1][0] * f[1] + r[2][0] * f[2],
                r[0][1] * f[0] + r[1][1] * f[1] + r[2][1] * f[2],
                r[0][2] * f[0] + r[1][2] * f[1] + r[2][2] * f[2],
            ];
            for (total, part) in torque.iter_mut().zip(cross(foot, &body_force)) {
                *total += part;
            }
        }
        for axis in 0..3 {
            d[3 + axis] += force[axis] * self.inv_mass;
            d[10 + axis] += torque[axis] * self.inv_inertia[axis];
        }
    }

    /// Sets the bristle of every foot above the ground to zero (lift-off), in a state whose
    /// last 8 values are the bristles.
    #[inline(always)]
    pub(crate) fn release_lifted_feet(&self, x: &mut [f64]) {
        let r = rotation(x[6], x[7], x[8], x[9]);
        let stretch = x.len() - BRISTLES;
        for (i, foot) in self.feet.iter().enumerate() {
            if x[2] + dot(&r[2], foot) > 0.0 {
                x[stretch + 2 * i] = 0.0;
                x[stretch + 2 * i + 1] = 0.0;
            }
        }
    }
}

/// Rotation matrix body → world of the quaternion (w, x, y, z), by rows.
#[inline(always)]
fn rotation(w: f64, x: f64, y: f64, z: f64) -> [[f64; 3]; 3] {
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

#[inline(always)]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quad's contact state: 13 body values, 4 motors, 8 bristles.
    const CONTACT_LEN: usize = 25;
    const STRETCH: usize = 17;
    use nalgebra::{UnitQuaternion, Vector3};

    /// The foot heights against nalgebra's rotation of each foot, tilted and turned.
    #[test]
    fn foot_heights_are_the_rotated_feet() {
        let p = QuadrotorParams::default();
        let body = BodyState::at_rest(Vector3::new(0.3, -0.2, 0.08), 0.4, -0.3, 1.1, 0.0);
        let q = UnitQuaternion::from_euler_angles(0.4, -0.3, 1.1);
        let heights = foot_heights(&p, &body);
        for (foot, height) in feet(&p).iter().zip(heights) {
            let world = q * Vector3::new(foot[0], foot[1], foot[2]);
            assert!((height - (0.08 + world.z)).abs() < 1e-15, "{height}");
        }
        // Positive roll lowers the right side: the right feet (0, 3) are the low ones.
        let rolled = BodyState::at_rest(Vector3::new(0.0, 0.0, 1.0), 0.3, 0.0, 0.0, 0.0);
        let h = foot_heights(&p, &rolled);
        assert!(h[0] < h[2] && h[3] < h[1], "{h:?}");
        assert_eq!(rotation(1.0, 0.0, 0.0, 0.0)[2], [0.0, 0.0, 1.0]);
    }

    /// At the rest height the four springs carry the weight exactly and nothing turns.
    #[test]
    fn at_rest_height_the_feet_carry_the_weight() {
        let p = QuadrotorParams::default();
        let z = rest_height(&p);
        assert!((z - (0.05 - 9.81 / 12000.0)).abs() < 1e-15, "{z}");
        let gear = Gear::new(&p);
        let mut x = [0.0; CONTACT_LEN];
        x[2] = z;
        x[6] = 1.0;
        let mut d = [0.0; CONTACT_LEN];
        gear.add_rates(&x, &mut d);
        assert!((d[5] - 9.81).abs() < 1e-12, "{}", d[5]);
        assert!(d[3].abs() < 1e-15 && d[4].abs() < 1e-15);
        assert!(
            d[10..13].iter().all(|a| a.abs() < 1e-12),
            "{:?}",
            &d[10..13]
        );
    }

    /// A sideways push on a sticking foot is the bristle's spring and damper; beyond μN the
    /// foot slips with exactly μN, and the bristle rate is continuous across the switch.
    #[test]
    fn friction_sticks_below_mu_n_and_slips_at_mu_n() {
        let p = QuadrotorParams::default();
        let gear = Gear::new(&p);
        let mut x = [0.0; CONTACT_LEN];
        x[6] = 1.0;
        // All four feet 1 mm deep: N = 3 N and μN = 1.5 N on each.
        x[2] = 0.049;
        let run = |stretch: f64, vx: f64| {
            let mut y = x;
            y[3] = vx;
            for i in 0..4 {
                y[STRETCH + 2 * i] = stretch;
            }
            let mut d = [0.0; CONTACT_LEN];
            gear.add_rates(&y, &mut d);
            (d[3] * p.mass / 4.0, d[STRETCH])
        };
        // Stick: F = −k s per foot, ṡ = v.
        let (f, rate) = run(1e-4, 0.0);
        assert!((f + 0.3).abs() < 1e-12 && rate == 0.0, "{f} {rate}");
        let (f, rate) = run(0.0, 0.01);
        assert!((f + 0.2).abs() < 1e-12 && rate == 0.01, "{f} {rate}");
        // Slip: |F| = μN = 1.5 N, ṡ = (−F − k s)/c.
        let (f, rate) = run(1e-3, 0.0);
        assert!((f + 1.5).abs() < 1e-12, "{f}");
        assert!((rate - (1.5 - 3.0) / 20.0).abs() < 1e-12, "{rate}");
        // Continuity at the boundary k s = μN.
        let (_, below) = run(0.5e-3 * (1.0 - 1e-9), 0.0);
        let (_, above) = run(0.5e-3 * (1.0 + 1e-9), 0.0);
        assert!((below - above).abs() < 1e-9, "{below} {above}");
    }
}
