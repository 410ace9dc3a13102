//! The policy's network: an ONNX graph evaluated by tract (float32), one observation row in,
//! one action row out. Loading checks the graph's input and output sizes against the recipe.

use crate::error::PolicyError;
use std::fmt;
use std::path::Path;
use tract_onnx::prelude::*;

type Plan = TypedRunnableModel<TypedModel>;

pub struct Network {
    plan: Plan,
    inputs: usize,
    outputs: usize,
}

impl fmt::Debug for Network {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Network({} -> {})", self.inputs, self.outputs)
    }
}

/// The one dimension of a `[1, n]` (or `[n]`) shape.
fn row_size(shape: &[usize]) -> Option<usize> {
    match shape {
        [n] | [1, n] => Some(*n),
        _ => None,
    }
}

impl Network {
    /// Loads `path` and checks that it maps `inputs` values to `outputs` values.
    pub fn load(path: &Path, inputs: usize, outputs: usize) -> Result<Network, PolicyError> {
        let fail = |field: &str, why: String| PolicyError::field(path, field, why);
        let model = tract_onnx::onnx().model_for_path(path).map_err(|e| {
            PolicyError::file(path, format!("is not an ONNX model tract reads: {e:#}"))
        })?;
        let typed = model
            .into_typed()
            .map_err(|e| PolicyError::file(path, format!("cannot be typed by tract: {e:#}")))?;
        if typed.inputs.len() != 1 || typed.outputs.len() != 1 {
            let why = format!(
                "the graph has {} inputs and {} outputs; a policy has one of each",
                typed.inputs.len(),
                typed.outputs.len()
            );
            return Err(PolicyError::file(path, why));
        }
        let size = |fact: TractResult<&TypedFact>| {
            fact.ok()
                .and_then(|f| f.shape.as_concrete().and_then(row_size))
        };
        let input_name = typed.node(typed.inputs[0].node).name.clone();
        match size(typed.input_fact(0)) {
            Some(n) if n == inputs => {}
            other => {
                let why = format!(
                    "takes {} values; the recipe's observation has {inputs}",
                    other.map_or("a shape other than [1, n] of".to_string(), |n| n
                        .to_string())
                );
                return Err(fail(&format!("input {input_name:?}"), why));
            }
        }
        let output_name = typed.node(typed.outputs[0].node).name.clone();
        match size(typed.output_fact(0)) {
            Some(n) if n == outputs => {}
            other => {
                let why = format!(
                    "gives {} values; the recipe has {outputs} actions",
                    other.map_or("a shape other than [1, n] of".to_string(), |n| n
                        .to_string())
                );
                return Err(fail(&format!("output {output_name:?}"), why));
            }
        }
        let plan = typed
            .into_optimized()
            .and_then(|m| m.into_runnable())
            .map_err(|e| PolicyError::file(path, format!("cannot be planned by tract: {e:#}")))?;
        Ok(Network {
            plan,
            inputs,
            outputs,
        })
    }

    /// The network's output for `observation` (its input size), or tract's error.
    pub fn run(&self, observation: &[f32]) -> Result<Vec<f32>, String> {
        let input =
            Tensor::from_shape(&[1, self.inputs], observation).map_err(|e| e.to_string())?;
        let out = self
            .plan
            .run(tvec!(input.into_tvalue()))
            .map_err(|e| format!("{e:#}"))?;
        let view = out
            .first()
            .ok_or("the network gave no output")?
            .to_array_view::<f32>()
            .map_err(|e| e.to_string())?;
        let values: Vec<f32> = view.iter().copied().collect();
        if values.len() != self.outputs {
            return Err(format!(
                "the network gave {} values, not {}",
                values.len(),
                self.outputs
            ));
        }
        Ok(values)
    }
}
