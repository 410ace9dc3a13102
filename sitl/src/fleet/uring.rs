//! The fleet thread's io_uring (Linux): a world step's writes to its PX4s in one system call,
//! and one sleep until every PX4 the world waits for has answered.
//!
//! Why: most of flyloop's CPU in a PX4 fleet is the kernel switching threads, not physics
//! (docs/performance.md, "Fleets").
//! - A write to a PX4's socket wakes the PX4 thread waiting for it with the hint that the
//!   writer is about to sleep (a socket's wake-up is a "sync" one), so that PX4 takes the fleet
//!   thread's CPU at the end of the write's system call: with one `send` per PX4 the fleet
//!   thread was preempted ~1.2 times per PX4 step. Submitted together, the writes run in one
//!   `io_uring_enter`, and the fleet thread is preempted at most once per world step.
//! - epoll wakes its waiter at the first answer; the world needs all of them. A poll request
//!   per awaited PX4 on a ring whose completions run only when its thread asks
//!   (`IORING_SETUP_DEFER_TASKRUN`) wakes the fleet thread once the last one has answered (or
//!   at the timeout): one wake-up per world step instead of one per answer or two.
//!
//! Where io_uring (or that setup) is not there — another OS, an old kernel, a container whose
//! seccomp profile forbids it — [`Uring::send`] and [`Uring::wait_readable`] say so and the
//! caller writes each socket itself and waits in epoll.

use std::os::fd::RawFd;

/// The environment variable and value that turn io_uring off: the fleet then runs as where
/// the kernel refuses it (to compare, or where io_uring misbehaves).
pub const OFF: (&str, &str) = ("FLYLOOP_IO_URING", "off");

/// One write: a socket and the bytes for it.
pub type Item<'a> = (RawFd, &'a [u8]);

#[cfg(target_os = "linux")]
pub use linux::Uring;

#[cfg(not(target_os = "linux"))]
#[derive(Debug, Default)]
pub struct Uring;

#[cfg(not(target_os = "linux"))]
impl Uring {
    pub fn new(_members: usize) -> Self {
        Uring
    }

    /// Never sends: the caller writes each socket itself.
    pub fn send(&mut self, _items: &[Item<'_>]) -> Option<Vec<std::io::Result<usize>>> {
        None
    }

    /// Never waits: the caller waits in its poll.
    pub fn wait_readable(
        &mut self,
        _fds: &[(usize, RawFd)],
        _timeout: std::time::Duration,
    ) -> Option<()> {
        None
    }

    pub fn disarm(&mut self, _i: usize) {}
}

#[cfg(target_os = "linux")]
mod linux {
    use super::{Item, OFF};
    use io_uring::{IoUring, opcode, types};
    use std::io;
    use std::os::fd::RawFd;
    use std::time::Duration;

    /// What a completion is for, in the top bits of its user data; the member or the write's
    /// index in the low ones.
    const SEND: u64 = 1 << 32;
    const POLL: u64 = 2 << 32;
    const CANCEL: u64 = 3 << 32;
    const INDEX: u64 = (1 << 32) - 1;

    struct Ring {
        ring: IoUring,
        /// Whether member i's socket has a poll request in flight.
        armed: Vec<bool>,
        /// The ring can wait for several completions in one sleep.
        waits: bool,
        /// The bytes of the writes in flight, owned here until their completions are read:
        /// the kernel reads them after `send` hands them over.
        buffers: Vec<Vec<u8>>,
        results: Vec<Option<io::Result<usize>>>,
    }

    /// The ring, or nothing if the kernel refused one.
    pub struct Uring {
        ring: Option<Ring>,
    }

    impl std::fmt::Debug for Uring {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.debug_struct("Uring")
                .field("io_uring", &self.ring.is_some())
                .finish()
        }
    }

    fn build(entries: u32) -> io::Result<(IoUring, bool)> {
        // Deferred completions need the ring to be used by the thread that made it only.
        let deferred = IoUring::builder()
            .setup_single_issuer()
            .setup_defer_taskrun()
            .build(entries);
        match deferred {
            Ok(ring) => {
                let waits = ring.params().is_feature_ext_arg();
                Ok((ring, waits))
            }
            Err(_) => IoUring::new(entries).map(|ring| (ring, false)),
        }
    }

    impl Uring {
        /// A ring for a fleet of `members` (made on the thread that will use it).
        pub fn new(members: usize) -> Self {
            if std::env::var(OFF.0).is_ok_and(|v| v == OFF.1) {
                tracing::info!(
                    "io_uring off ({}={}): the fleet writes each PX4's socket with its own system call and waits in epoll",
                    OFF.0,
                    OFF.1
                );
                return Uring { ring: None };
            }
            let entries = (2 * members).clamp(2, 4096).next_power_of_two() as u32;
            let ring = match build(entries) {
                Ok((ring, waits)) => {
                    if !waits {
                        tracing::info!(
                            "io_uring without deferred completions: the fleet waits for its PX4s in epoll"
                        );
                    }
                    Some(Ring {
                        ring,
                        armed: vec![false; members],
                        waits,
                        buffers: Vec::new(),
                        results: Vec::new(),
                    })
                }
                Err(e) => {
                    tracing::info!(error = %e, "no io_uring: the fleet writes each PX4's socket with its own system call and waits in epoll");
                    None
                }
            };
            Uring { ring }
        }

        /// Sends every item without blocking, all in one system call; returns per item the
        /// bytes sent or the error (`WouldBlock` when its socket is full). `None`: nothing
        /// was sent, the caller writes each socket itself.
        pub fn send(&mut self, items: &[Item<'_>]) -> Option<Vec<io::Result<usize>>> {
            let r = self.ring.as_mut()?;
            let free = {
                let sq = r.ring.submission();
                sq.capacity() - sq.len()
            };
            if items.len() > free {
                return None;
            }
            r.buffers.resize_with(items.len(), Vec::new);
            for (buffer, (_, bytes)) in r.buffers.iter_mut().zip(items) {
                buffer.clear();
                buffer.extend_from_slice(bytes);
            }
            let flags = libc::MSG_DONTWAIT | libc::MSG_NOSIGNAL;
            for (k, ((fd, _), buffer)) in items.iter().zip(&r.buffers).enumerate() {
                let send = opcode::Send::new(types::Fd(*fd), buffer.as_ptr(), buffer.len() as u32)
                    .flags(flags)
                    .build()
                    .user_data(SEND | k as u64);
                // SAFETY: the buffer stays in `r.buffers`, untouched, until this write's
                // completion is read below (or forever, if the ring fails first); there is
                // room for every entry (checked above).
                let _ = unsafe { r.ring.submission().push(&send) };
            }
            r.results.clear();
            r.results.resize_with(items.len(), || None);
            let mut left = items.len();
            while left > 0 {
                match r.ring.submit_and_wait(left) {
                    Ok(_) => {}
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                    Err(e) => {
                        tracing::warn!(error = %e, "io_uring failed: the fleet writes each PX4's socket with its own system call from now on");
                        let results = std::mem::take(&mut r.results);
                        self.abandon();
                        return Some(
                            (results.into_iter())
                                .map(|r| r.unwrap_or_else(|| Err(io::Error::other(e.to_string()))))
                                .collect(),
                        );
                    }
                }
                left -= reap(r);
            }
            Some(r.results.drain(..).map(|r| r.unwrap_or(Ok(0))).collect())
        }

        /// Sleeps until every socket of `fds` (member, socket) is readable, or `timeout`
        /// passed; `None`: it cannot, the caller waits in its poll.
        pub fn wait_readable(&mut self, fds: &[(usize, RawFd)], timeout: Duration) -> Option<()> {
            let r = self.ring.as_mut().filter(|r| r.waits)?;
            let free = {
                let sq = r.ring.submission();
                sq.capacity() - sq.len()
            };
            if fds.len() > free || fds.iter().any(|&(i, _)| i >= r.armed.len()) {
                return None;
            }
            for &(i, fd) in fds {
                if !r.armed[i] {
                    let poll = opcode::PollAdd::new(types::Fd(fd), libc::POLLIN as u32)
                        .build()
                        .user_data(POLL | i as u64);
                    // SAFETY: a poll request points at no memory of ours.
                    let _ = unsafe { r.ring.submission().push(&poll) };
                    r.armed[i] = true;
                }
            }
            let timespec = types::Timespec::from(timeout);
            let args = types::SubmitArgs::new().timespec(&timespec);
            match r.ring.submitter().submit_with_args(fds.len(), &args) {
                Ok(_) => {}
                Err(e) if e.raw_os_error() == Some(libc::ETIME) => {}
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => {
                    tracing::warn!(error = %e, "io_uring wait failed: the fleet waits in epoll from now on");
                    r.waits = false;
                }
            }
            reap(r);
            Some(())
        }

        /// Takes member i's poll request back, before its socket closes (a request in flight
        /// keeps the socket open).
        pub fn disarm(&mut self, i: usize) {
            let Some(r) = self.ring.as_mut() else {
                return;
            };
            if !r.armed.get(i).copied().unwrap_or(false) {
                return;
            }
            let cancel = opcode::AsyncCancel::new(POLL | i as u64)
                .build()
                .user_data(CANCEL | i as u64);
            // SAFETY: a cancel request points at no memory of ours.
            if unsafe { r.ring.submission().push(&cancel) }.is_err() {
                let _ = r.ring.submit();
                // SAFETY: as above.
                let _ = unsafe { r.ring.submission().push(&cancel) };
            }
            for _ in 0..10 {
                let timespec = types::Timespec::from(Duration::from_millis(100));
                let args = types::SubmitArgs::new().timespec(&timespec);
                let waited = r.ring.submitter().submit_with_args(1, &args);
                reap(r);
                if !r.armed[i] {
                    return;
                }
                if let Err(e) = waited {
                    if e.raw_os_error() != Some(libc::ETIME)
                        && e.kind() != io::ErrorKind::Interrupted
                    {
                        break;
                    }
                }
            }
            tracing::warn!(
                "io_uring did not give member {i}'s poll back: the ring is left as it is"
            );
            self.abandon();
        }

        /// Stops using the ring. Requests may still be in flight and point at its buffers, so
        /// it is leaked, not dropped.
        fn abandon(&mut self) {
            if let Some(ring) = self.ring.take() {
                std::mem::forget(ring);
            }
        }
    }

    /// Reads every completion; returns how many were writes'.
    fn reap(r: &mut Ring) -> usize {
        let mut sends = 0;
        for cqe in r.ring.completion() {
            let (kind, k) = (cqe.user_data() & !INDEX, (cqe.user_data() & INDEX) as usize);
            let result = cqe.result();
            match kind {
                SEND => {
                    if let Some(slot @ None) = r.results.get_mut(k) {
                        *slot = Some(if result >= 0 {
                            Ok(result as usize)
                        } else {
                            Err(io::Error::from_raw_os_error(-result))
                        });
                        sends += 1;
                    }
                }
                POLL => {
                    if let Some(armed) = r.armed.get_mut(k) {
                        *armed = false;
                    }
                }
                _ => {}
            }
        }
        sends
    }
}
