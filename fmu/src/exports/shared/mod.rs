//! What FMI 2.0 and FMI 3.0 share below their C signatures: the functions that are the same
//! in both versions, declared once for both ([`twins!`]: freeing and configuring instances,
//! FMU states, most of Model Exchange), and the bodies of those that differ only in their
//! signatures (instantiation, the experiment, the event update).

pub(crate) mod fmu_state;
pub(crate) mod instantiate;
pub(crate) mod lifecycle;
pub(crate) mod model_exchange;
