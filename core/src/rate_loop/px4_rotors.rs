//! PX4's description of a frame: the `CA_ROTORn_PX/PY/KM/CT` parameters of its control
//! allocator, generated from the frame's rotor table. One function for both users: the SITL
//! prints them for a real PX4 (`--print-autopilot-params px4`) and the rate-loop model builds
//! its allocation from them ([`super::allocation`]), so the model mixes as PX4 does.
//!
//! The quad X is the exception that keeps one airframe one set of numbers: PX4 flies it with
//! its stock airframe 10016 `none_iris`, whose rotors are the real Iris's (0.1515 m fore and
//! aft, 0.245 m / 0.1875 m to the side, KM 0.05, CT 6.5; ROMFS `10016_none_iris`), not the
//! table's symmetric square. Those are the numbers PX4 mixes the quad X with, so they are the
//! quad X's PX4 numbers here too (the model was validated against them).

use crate::quadrotor::{Frame, QuadrotorParams};

/// One rotor as PX4's control allocator parameters describe it (body FRD).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Px4Rotor {
    /// `CA_ROTORn_PX`: position forward of the centre of mass, m.
    pub px: f64,
    /// `CA_ROTORn_PY`: position right of the centre of mass, m.
    pub py: f64,
    /// `CA_ROTORn_KM`: yaw moment per unit thrust, m; positive for a counter-clockwise rotor.
    pub km: f64,
    /// `CA_ROTORn_CT`: thrust coefficient (flyloop: thrust at full motor state, N).
    pub ct: f64,
}

/// PX4 v1.16.0's airframe 10016 `none_iris`: front right, rear left, front left, rear right.
pub const NONE_IRIS: [Px4Rotor; 4] = [
    Px4Rotor {
        px: 0.1515,
        py: 0.245,
        km: 0.05,
        ct: 6.5,
    },
    Px4Rotor {
        px: -0.1515,
        py: -0.1875,
        km: 0.05,
        ct: 6.5,
    },
    Px4Rotor {
        px: 0.1515,
        py: -0.245,
        km: -0.05,
        ct: 6.5,
    },
    Px4Rotor {
        px: -0.1515,
        py: 0.1875,
        km: -0.05,
        ct: 6.5,
    },
];

/// PX4's rotors for `frame` on the vehicle `params`, in motor order (PX4 output n drives rotor
/// n): the stock none_iris table for the quad X, the frame's table otherwise (positions in
/// metres, FLU's y turned to FRD's, KM from the spin and the torque coefficient).
pub fn px4_rotors(frame: &Frame, params: &QuadrotorParams) -> Vec<Px4Rotor> {
    if frame.is_quad_x() {
        return NONE_IRIS.to_vec();
    }
    (frame.rotors().iter())
        .map(|r| Px4Rotor {
            px: params.arm_length * r.x,
            py: -params.arm_length * r.y,
            km: -r.spin.sign()
                * r.torque_coefficient
                    .unwrap_or(params.yaw_torque_coefficient),
            ct: r.thrust_coefficient.unwrap_or(params.thrust_coefficient),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quad_x_is_px4s_none_iris_and_other_frames_their_table() {
        let p = QuadrotorParams::default();
        assert_eq!(px4_rotors(&Frame::quad_x(), &p), NONE_IRIS.to_vec());
        let hexa = px4_rotors(&Frame::named("hexa_x").unwrap(), &p);
        assert_eq!(hexa.len(), 6);
        // Rotor 0 of PX4's 6001 hexa_x: straight right (FRD y > 0), clockwise (KM < 0).
        assert_eq!((hexa[0].px, hexa[0].py), (0.0, p.arm_length));
        assert_eq!(hexa[0].km, -p.yaw_torque_coefficient);
        assert_eq!(hexa[1].km, p.yaw_torque_coefficient);
        assert!(hexa.iter().all(|r| r.ct == p.thrust_coefficient));
    }
}
