//! The `flyloop-sitl` binary: the whole program lives in [`flyloop_sitl::app`], so the Python
//! wheel's `flyloop-sitl` command runs exactly the same code.

fn main() -> std::process::ExitCode {
    std::process::ExitCode::from(flyloop_sitl::app::main_with_args(std::env::args_os()))
}
