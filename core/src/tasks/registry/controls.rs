//! How every front end treats an action before the task takes it.

/// Why a set of controls was refused.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ControlError {
    #[error("controls[{channel}] = {value}: step refused")]
    NotFinite { channel: usize, value: f32 },
}

/// Checks `controls` (the first `lo.len()` channels are used, missing ones are 0; each used
/// one must be finite) and writes them clamped into [lo, hi] to `command`; returns whether any
/// was clamped. On error `command` is unchanged. The SITL and the Python extension both
/// treat actions through here.
pub fn clamp_controls(
    controls: &[f32],
    lo: &[f64],
    hi: &[f64],
    command: &mut Vec<f64>,
) -> Result<bool, ControlError> {
    let n = lo.len();
    if let Some((channel, &value)) = controls
        .iter()
        .take(n)
        .enumerate()
        .find(|(_, c)| !c.is_finite())
    {
        return Err(ControlError::NotFinite { channel, value });
    }
    let mut clamped = false;
    command.clear();
    for i in 0..n {
        let c = controls.get(i).map_or(0.0, |&c| f64::from(c));
        let v = c.clamp(lo[i], hi[i]);
        clamped |= v != c;
        command.push(v);
    }
    Ok(clamped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controls_are_clamped_missing_ones_zero_and_non_finite_ones_refused() {
        let (lo, hi) = ([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0]);
        let mut command = vec![7.0];
        assert_eq!(
            clamp_controls(&[2.0, -0.5], &lo, &hi, &mut command),
            Ok(true)
        );
        assert_eq!(command, vec![1.0, -0.5, 0.0]);
        assert_eq!(
            clamp_controls(&[0.5, 0.5, 0.5, 9.0], &lo, &hi, &mut command),
            Ok(false)
        );
        assert_eq!(
            command,
            vec![0.5, 0.5, 0.5],
            "channels past the bounds are ignored"
        );
        let err = clamp_controls(&[0.0, f32::INFINITY], &lo, &hi, &mut command).unwrap_err();
        assert_eq!(err.to_string(), "controls[1] = inf: step refused");
        assert_eq!(
            command,
            vec![0.5, 0.5, 0.5],
            "a refused command changes nothing"
        );
    }
}
