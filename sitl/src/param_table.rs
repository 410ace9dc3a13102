//! The parameter listing of `flyloop-sitl --list-params` and the docs. The rows themselves
//! (names, short ids, sets, ranges) are the core's
//! [`param_rows`](flyloop_core::tasks::registry::param_rows).

use flyloop_core::params::ValueKind;
use flyloop_core::tasks::registry::param_rows::{entries, get};
use flyloop_core::tasks::registry::{TaskConfig, TaskKind};

/// A readable listing of `task`'s parameters (for `--list-params` and the docs).
pub fn listing(task: TaskKind, config: &TaskConfig) -> String {
    let mut out = String::from(
        "| param_id | core name | set | type | unit | default | range |\n|---|---|---|---|---|---|---|\n",
    );
    for e in entries(task) {
        let value = get(config, e.group, e.name).unwrap_or(f64::NAN);
        let (kind, range) = match e.kind {
            ValueKind::Real => ("REAL32", format!("[{}, {}]", e.min, e.max)),
            ValueKind::Integer => ("INT32", format!("[{}, {}]", e.min, e.max)),
            ValueKind::Boolean => ("UINT8", "0 / 1".to_string()),
        };
        let name = if e.id == e.name {
            String::new()
        } else {
            format!("`{}`", e.name)
        };
        out.push_str(&format!(
            "| `{}` | {} | {} | {} | {} | {} | {} |\n",
            e.id,
            name,
            e.group.label(),
            kind,
            e.unit,
            value,
            range
        ));
    }
    out
}
