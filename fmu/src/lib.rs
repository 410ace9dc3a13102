//! FMI 2.0 Co-Simulation front end of flyloop-core (work in progress, issue 4).
