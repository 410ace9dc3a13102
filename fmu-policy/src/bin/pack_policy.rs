//! flyloop-fmu-pack-policy: packs a trained policy into Policy.fmu (FMI 2.0) and
//! `<stem>-fmi3.fmu` (FMI 3.0). `flyloop-fmu-pack policy …` runs it.
//!
//! ```text
//! flyloop-fmu-pack-policy POLICY_DIR -o Policy.fmu [--library libflyloop_fmu_policy.so]
//! ```
//!
//! The library defaults to `libflyloop_fmu_policy.so` next to this program.

use flyloop_fmu_policy::pack::pack;
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str =
    "usage: flyloop-fmu-pack policy POLICY_DIR -o Policy.fmu [--library libflyloop_fmu_policy.so]";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut folder, mut out, mut library) = (None, None, None);
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "-o" | "--output" => out = it.next().map(PathBuf::from),
            "--library" => library = it.next().map(PathBuf::from),
            _ if folder.is_none() && !arg.starts_with('-') => folder = Some(PathBuf::from(arg)),
            _ => {
                eprintln!("{USAGE}");
                return ExitCode::from(2);
            }
        }
    }
    let (Some(folder), Some(out)) = (folder, out) else {
        eprintln!("{USAGE}");
        return ExitCode::from(2);
    };
    let library = library.unwrap_or_else(|| {
        let exe = std::env::current_exe().unwrap_or_default();
        exe.with_file_name("libflyloop_fmu_policy.so")
    });
    match pack(&folder, &library, &out) {
        Ok(paths) => {
            paths.iter().for_each(|p| println!("{}", p.display()));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("flyloop-fmu-pack policy: {e}");
            ExitCode::FAILURE
        }
    }
}
