//! docs/parameters.md is the parameter tables, verbatim.

#[test]
fn docs_parameters_md_matches_the_parameter_tables() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/parameters.md");
    let checked_in = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        checked_in == flyloop_core::reference::parameter_reference(),
        "docs/parameters.md is out of date; regenerate it with\n  \
         cargo run -p flyloop-core --example parameter_reference > docs/parameters.md"
    );
}
