//! Prints the parameter reference (docs/parameters.md) from the parameter tables.
//!
//! cargo run -p flyloop-core --example parameter_reference > docs/parameters.md

fn main() {
    print!("{}", flyloop_core::reference::parameter_reference());
}
