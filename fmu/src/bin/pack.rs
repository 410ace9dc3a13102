//! flyloop-fmu-pack: writes Quadrotor.fmu and Lander2D.fmu, or the checked-in
//! modelDescription copies.
//!
//! ```text
//! flyloop-fmu-pack fmus <libflyloop_fmu.so> <out-dir>
//! flyloop-fmu-pack model-descriptions <dir>
//! ```
//!
//! scripts/pack-fmus.sh builds the library and runs the first form into dist/fmu.

use flyloop_fmu::models::tables;
use flyloop_fmu::pack::{write_fmu, write_model_description};
use std::path::Path;
use std::process::ExitCode;

const USAGE: &str = "usage: flyloop-fmu-pack fmus <libflyloop_fmu.so> <out-dir>\n       \
                     flyloop-fmu-pack model-descriptions <dir>";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let result = match args.as_slice() {
        ["fmus", library, out] => tables()
            .into_iter()
            .map(|t| write_fmu(t, Path::new(library), Path::new(out)))
            .collect::<Result<Vec<_>, _>>(),
        ["model-descriptions", dir] => tables()
            .into_iter()
            .map(|t| write_model_description(t, Path::new(dir)))
            .collect::<Result<Vec<_>, _>>(),
        _ => {
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(paths) => {
            for path in paths {
                println!("{}", path.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("flyloop-fmu-pack: {e}");
            ExitCode::FAILURE
        }
    }
}
