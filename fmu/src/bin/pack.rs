//! flyloop-fmu-pack: writes every FMU of the library — Quadrotor.fmu, Lander2D.fmu,
//! Hexacopter.fmu and RateController.fmu (FMI 2.0) and their `-fmi3.fmu` twins (FMI 3.0) — or
//! the checked-in modelDescription copies of all eight.
//!
//! ```text
//! flyloop-fmu-pack fmus <libflyloop_fmu.so> <out-dir>
//! flyloop-fmu-pack model-descriptions <dir>
//! flyloop-fmu-pack policy <POLICY_DIR> -o <Policy.fmu>
//! ```
//!
//! `policy` runs `flyloop-fmu-pack-policy` from next to this program (crate
//! flyloop-fmu-policy, which links tract; this library does not).
//!
//! scripts/pack-fmus.sh builds the library and runs the first form into dist/fmu.

use flyloop_fmu::api::Api;
use flyloop_fmu::models::tables;
use flyloop_fmu::pack::{write_fmu, write_model_description};
use std::path::Path;
use std::process::ExitCode;

const USAGE: &str = "usage: flyloop-fmu-pack fmus <libflyloop_fmu.so> <out-dir>\n       \
                     flyloop-fmu-pack model-descriptions <dir>\n       \
                     flyloop-fmu-pack policy <POLICY_DIR> -o <Policy.fmu>";

/// Runs the policy packer (a program of the flyloop-fmu-policy crate) next to this one.
fn pack_policy(args: &[String]) -> ExitCode {
    let exe = std::env::current_exe().unwrap_or_default();
    let packer = exe.with_file_name("flyloop-fmu-pack-policy");
    match std::process::Command::new(&packer).args(args).status() {
        Ok(status) if status.success() => ExitCode::SUCCESS,
        Ok(_) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!(
                "flyloop-fmu-pack policy: {} cannot run ({e}); build it with \
                 `cargo build --release -p flyloop-fmu-policy`",
                packer.display()
            );
            ExitCode::FAILURE
        }
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("policy") {
        return pack_policy(&args[1..]);
    }
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
