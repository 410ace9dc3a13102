//! MAVLink SITL front end of flyloop-core (work in progress, issue 5).

fn main() {}
