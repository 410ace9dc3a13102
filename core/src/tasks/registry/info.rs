//! The info dictionary flattened to float32 values, as the SITL's task frame and the Python
//! extension's info arrays carry it.

use super::TaskInstance;
use crate::tasks::InfoRef;

/// Appends one info value's numbers to `out` (flags as 0 or 1).
pub fn push_info(out: &mut Vec<f32>, value: InfoRef<'_>) {
    match value {
        InfoRef::Real(x) => out.push(x as f32),
        InfoRef::Integer(i) => out.push(i as f32),
        InfoRef::Flag(b) => out.push(if b { 1.0 } else { 0.0 }),
        InfoRef::Vector(v) => out.extend(v.iter().map(|x| *x as f32)),
    }
}

/// Appends every info value of `task`, flattened in the task's info order (no allocation
/// beyond `out`'s: the vector env calls this for every env every step).
pub fn push_infos(task: &TaskInstance, out: &mut Vec<f32>) {
    task.visit_info(&mut |_, value| push_info(out, value));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tasks::registry::{TaskConfig, TaskKind};

    #[test]
    fn info_values_flatten_in_order() {
        let mut out = vec![9.0];
        push_info(&mut out, InfoRef::Flag(true));
        push_info(&mut out, InfoRef::Integer(-3));
        push_info(&mut out, InfoRef::Vector(&[0.5, 2.0]));
        assert_eq!(out, vec![9.0, 1.0, -3.0, 0.5, 2.0]);
        let task = TaskInstance::build(TaskKind::Hover, &TaskConfig::default()).unwrap();
        let mut all = Vec::new();
        push_infos(&task, &mut all);
        assert_eq!(all.len(), 12);
    }
}
