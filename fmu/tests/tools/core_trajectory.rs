//! Prints the trajectory of the core model, stepped directly from Rust (no FMU), for the
//! experiment read as JSON from stdin. The Python system tests compare it with what fmpy
//! gets from the FMU for the same experiment.
//!
//! ```text
//! input:  {"model": "Quadrotor" | "Hexacopter" | "Lander2D", "start_values": {"seed": 7, ...},
//!          "step_size": 0.01, "steps": 300,
//!          "inputs": [{"time": 0.0, "values": {"motor_command_0": 0.5, ...}}, ...],
//!          "outputs": ["x", "z", ...]}
//! output: {"time": [...], "x": [...], "z": [...]}   (one row at t = 0, one per step)
//!
//! echo '{...}' | target/release/flyloop-fmu-core-trajectory
//! ```
//!
//! Before the step that starts at n·h, every input change with time <= n·h is applied.
// A test reference tool: input it cannot use ends the run with a panic message naming it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use flyloop_core::Parameters;
use flyloop_core::lander2d::{Lander2d, Lander2dInitial, Lander2dParams};
use flyloop_core::quadrotor::{Frame, Quadrotor, QuadrotorInitial, QuadrotorParams};
use flyloop_core::variables::{Rows, VariableTable};
use serde_json::{Map, Value, json};
use std::io::Read;

/// A core model seen through its own variable table.
struct Core<M: VariableTable> {
    model: M,
    initial: M::Initial,
    rows: Rows<M>,
}

impl<M: VariableTable> Core<M> {
    fn new(model: M, initial: M::Initial) -> Self {
        let rows = Rows::of_model(&model);
        Core {
            model,
            initial,
            rows,
        }
    }
    fn get(&self, vr: u32) -> f64 {
        self.rows.get(&self.model, &self.initial, vr).unwrap()
    }
    fn set(&mut self, vr: u32, value: f64) {
        (self.rows.set(&mut self.model, &mut self.initial, vr, value)).unwrap();
    }
}

/// How a model moves to the end of a communication step.
trait Advance {
    fn advance(&mut self, end_time: f64, step_size: f64);
}

impl Advance for Quadrotor {
    fn advance(&mut self, _end_time: f64, step_size: f64) {
        self.step(step_size);
    }
}

impl Advance for Lander2d {
    fn advance(&mut self, end_time: f64, _step_size: f64) {
        // To the state at end_time, as the FMU does (whole physics substeps on their grid,
        // a shortened one inside a substep).
        self.advance_to(end_time);
    }
}

/// Splits start values between the physical parameters and the initial values.
fn start_values<P: Parameters, I: Parameters>(values: &Map<String, Value>) -> (P, I) {
    let (mut params, mut initial) = (P::default(), I::default());
    for (name, value) in values {
        let value = value
            .as_f64()
            .or_else(|| value.as_bool().map(f64::from))
            .unwrap();
        if params.set(name, value).is_err() {
            initial
                .set(name, value)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
    (params, initial)
}

fn run<M: VariableTable + Advance>(mut core: Core<M>, spec: &Value) -> Value {
    let variables = core.rows.variables();
    let vr = |name: &str| {
        variables
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("no variable {name}"))
            .value_reference
    };
    let h = spec["step_size"].as_f64().unwrap();
    let steps = spec["steps"].as_u64().unwrap();
    let outputs: Vec<&str> = spec["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o.as_str().unwrap())
        .collect();
    let inputs = spec["inputs"].as_array().cloned().unwrap_or_default();
    let mut next_input = 0;
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); outputs.len() + 1];
    let record = |core: &Core<M>, t: f64, columns: &mut Vec<Vec<f64>>| {
        columns[0].push(t);
        for (column, name) in columns[1..].iter_mut().zip(&outputs) {
            column.push(core.get(vr(name)));
        }
    };
    record(&core, 0.0, &mut columns);
    for n in 0..steps {
        let t = n as f64 * h;
        while next_input < inputs.len() && inputs[next_input]["time"].as_f64().unwrap() <= t {
            for (name, value) in inputs[next_input]["values"].as_object().unwrap() {
                core.set(vr(name), value.as_f64().unwrap());
            }
            next_input += 1;
        }
        let end = (n + 1) as f64 * h;
        core.model.advance(end, h);
        record(&core, end, &mut columns);
    }
    let mut out = Map::new();
    out.insert("time".into(), json!(columns[0]));
    for (name, column) in outputs.iter().zip(&columns[1..]) {
        out.insert((*name).into(), json!(column));
    }
    Value::Object(out)
}

fn main() {
    let mut text = String::new();
    std::io::stdin().read_to_string(&mut text).unwrap();
    let spec: Value = serde_json::from_str(&text).unwrap();
    let values = spec["start_values"]
        .as_object()
        .cloned()
        .unwrap_or_default();
    let model = spec["model"].as_str().unwrap();
    // The multirotor FMUs and their frames.
    let frame = match model {
        "Quadrotor" => Some("quad_x"),
        "Hexacopter" => Some("hexa_x"),
        _ => None,
    };
    let result = match (model, frame) {
        (_, Some(frame)) => {
            let (params, initial) = start_values::<QuadrotorParams, QuadrotorInitial>(&values);
            let quad = Quadrotor::from_initial(params, &initial).unwrap();
            let quad = quad.with_frame(Frame::named(frame).unwrap());
            run(Core::new(quad, initial), &spec)
        }
        ("Lander2D", None) => {
            let (params, initial) = start_values::<Lander2dParams, Lander2dInitial>(&values);
            let lander = Lander2d::from_initial(params, &initial).unwrap();
            run(Core::new(lander, initial), &spec)
        }
        _ => panic!("unknown model {model}"),
    };
    println!("{result}");
}
