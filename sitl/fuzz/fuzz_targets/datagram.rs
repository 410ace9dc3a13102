//! Any bytes, on either link, in lockstep or real time: the handler must not panic, and a
//! valid step that follows must still be answered (checked by `flyloop_sitl::fuzz::datagram`,
//! which a normal test of the sitl crate also runs on fixed inputs).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| flyloop_sitl::fuzz::datagram(data));
