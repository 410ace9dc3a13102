//! The GUID of an FMU, derived from its interface: the model identifier and every variable's
//! name, value reference, type, causality, variability, unit, start and range. The same code
//! writes it into the modelDescription and checks it in fmi2Instantiate, so the two cannot
//! drift apart; any change of the interface gives a new GUID.

use crate::api::Api;
use flyloop_core::variables::Variable;
use std::fmt::Write;

/// FNV-1a 64 over `bytes`, starting from `basis`.
fn fnv1a64(basis: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(basis, |hash, &b| {
        (hash ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// `{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}` for the interface of `identifier` in `api` (FMI
/// 2.0's GUID, FMI 3.0's instantiationToken): the header differs, so that an FMI 2.0
/// modelDescription never instantiates through FMI 3.0 or the other way round.
pub fn of_interface(api: Api, identifier: &str, variables: &[Variable]) -> String {
    let mut text = match api {
        Api::Fmi2 => format!("flyloop FMI 2.0 CS {identifier}\n"),
        Api::Fmi3 => format!("flyloop FMI 3.0 {identifier}\n"),
    };
    for v in variables {
        // Debug of f64 is the shortest exact form: equal text ⇔ equal values.
        let _ = writeln!(
            text,
            "{}|{}|{:?}|{:?}|{:?}|{}|{:?}|{:?}|{:?}",
            v.name,
            v.value_reference,
            v.kind,
            v.causality,
            v.variability,
            v.unit,
            v.start,
            v.min,
            v.max
        );
    }
    let a = fnv1a64(0xcbf2_9ce4_8422_2325, text.as_bytes());
    let b = fnv1a64(0x6c62_272e_07bb_0142, text.as_bytes());
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use flyloop_core::quadrotor::{Frame, Quadrotor};
    use flyloop_core::variables::Rows;

    #[test]
    fn guid_has_the_uuid_shape_and_follows_the_interface() {
        let vars = Rows::<Quadrotor>::of(&Frame::quad_x()).variables();
        let guid = of_interface(Api::Fmi2, "Quadrotor", &vars);
        assert_eq!(guid.len(), 38, "{guid}");
        assert!(guid.starts_with('{') && guid.ends_with('}'));
        let groups: Vec<usize> = guid[1..37].split('-').map(str::len).collect();
        assert_eq!(groups, [8, 4, 4, 4, 12]);
        assert_eq!(
            guid,
            of_interface(Api::Fmi2, "Quadrotor", &vars),
            "deterministic"
        );
        assert_ne!(guid, of_interface(Api::Fmi2, "Other", &vars));
        let mut changed = vars.clone();
        changed[0].max = Some(2.0);
        assert_ne!(guid, of_interface(Api::Fmi2, "Quadrotor", &changed));
        // Another frame is another interface (six motor commands and states).
        let hexa = Frame::named("hexa_x").unwrap();
        let hexa = Rows::<Quadrotor>::of(&hexa).variables();
        assert_ne!(guid, of_interface(Api::Fmi2, "Quadrotor", &hexa));
    }
}
