//! The fleet thread's scheduling priority. Every autopilot of the fleet waits for it at
//! each step (it reads the answers, steps the world and writes the sensors), yet it needs
//! only ~5 % of the fleet's CPU. On a busy machine the kernel preempts it whenever a PX4 it
//! has just written to wakes up, and each preemption stalls the whole fleet for a
//! scheduling turn (measured: 8 PX4s at load 20–27 ran 0.5–1.3× real time, the fleet
//! thread waiting 44 s of 67 s on the run queue; docs/performance.md "Fleets"). A higher
//! priority (a lower nice value) keeps the barrier moving and, being only the fleet
//! thread's, cannot starve anyone.

/// The fleet thread's nice value where the process may raise its priority (root or
/// CAP_SYS_NICE); elsewhere it keeps the default (0).
pub const FLEET_THREAD_NICE: i32 = -10;

/// Gives the calling thread [`FLEET_THREAD_NICE`]; says in the log whether it could.
pub fn favour_this_thread() {
    // SAFETY: gettid and setpriority take no pointers; a thread may set its own priority.
    let done = unsafe {
        let tid = libc::gettid();
        libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, FLEET_THREAD_NICE)
    };
    if done == 0 {
        tracing::info!(nice = FLEET_THREAD_NICE, "fleet thread priority raised");
    } else {
        let e = std::io::Error::last_os_error();
        tracing::info!(error = %e, "fleet thread priority left at the default (needs CAP_SYS_NICE)");
    }
}
