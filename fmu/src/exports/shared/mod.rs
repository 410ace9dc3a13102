//! What FMI 2.0 and FMI 3.0 share below their C signatures: creating, configuring and
//! freeing instances, FMU states and Model Exchange. Each body takes the function's name for
//! its log messages and answers an FMI 2.0 status (FMI 3.0 converts it).

pub(crate) mod fmu_state;
pub(crate) mod instantiate;
pub(crate) mod lifecycle;
pub(crate) mod model_exchange;
