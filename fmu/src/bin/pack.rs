//! flyloop-fmu-pack: writes every FMU of the library — Quadrotor.fmu, Lander2D.fmu,
//! Hexacopter.fmu and RateController.fmu (FMI 2.0) and their `-fmi3.fmu` twins (FMI 3.0) — or
//! the checked-in modelDescription copies of all eight.
//!
//! ```text
//! flyloop-fmu-pack fmus <libflyloop_fmu.so> <out-dir>
//! flyloop-fmu-pack model-descriptions <dir>
//! ```
//!
//! scripts/pack-fmus.sh builds the library and runs the first form into dist/fmu.

use flyloop_fmu::api::Api;
use flyloop_fmu::models::tables;
use flyloop_fmu::pack::{write_fmu, write_model_description};
use std::path::Path;
use std::process::ExitCode;

const USAGE: &str = "usage: flyloop-fmu-pack fmus <libflyloop_fmu.so> <out-dir>\n       \
                     flyloop-fmu-pack model-descriptions <dir>";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    for (table, version) in Api::ALL.into_iter().flat_map(|v| tables().map(|t| (t, v))) {
        let written = match args.as_slice() {
            ["fmus", library, out] => write_fmu(table, version, Path::new(library), Path::new(out)),
            ["model-descriptions", dir] => write_model_description(table, version, Path::new(dir)),
            _ => {
                eprintln!("{USAGE}");
                return ExitCode::from(2);
            }
        };
        match written {
            Ok(path) => println!("{}", path.display()),
            Err(e) => {
                eprintln!("flyloop-fmu-pack: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}
