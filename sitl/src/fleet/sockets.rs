//! The fleet's sockets, read by the fleet thread itself through one readiness poll (`mio`,
//! epoll on Linux): every PX4's listener and connection, every ArduPilot's UDP port.
//!
//! Why one poll and not a thread per socket: in lockstep each PX4 answers every sensor
//! message, so a thread per socket is woken once per PX4 step and must wake the fleet thread
//! in turn; those wake-ups were most of flyloop's CPU in a PX4 fleet (docs/performance.md,
//! "Fleets"). One poll reads every answer that arrived while the fleet thread was busy or
//! asleep in one wake-up.

use super::file::Autopilot;
use super::uring::{Item, Uring};
use super::{Fleet, Member};
use crate::server::is_retry;
use mio::net::{TcpListener, TcpStream, UdpSocket};
use mio::{Events, Interest, Poll, Token};
use std::io::{self, Read, Write};
use std::net::SocketAddr;
use std::os::fd::{AsRawFd, RawFd};
use std::time::Duration;

/// The fleet's sockets, bound before the SITL says it is ready.
#[derive(Debug)]
pub enum Socket {
    Px4(std::net::TcpListener),
    ArduPilot(std::net::UdpSocket),
}

impl Socket {
    /// The port it is bound to (an ephemeral one when asked for port 0).
    pub fn port(&self) -> io::Result<u16> {
        match self {
            Socket::Px4(listener) => listener.local_addr().map(|a| a.port()),
            Socket::ArduPilot(socket) => socket.local_addr().map(|a| a.port()),
        }
    }
}

/// Sockets of `fleet`'s autopilots, in its (name) order.
pub fn bind(fleet: &Fleet) -> Result<Vec<Socket>, (String, SocketAddr, io::Error)> {
    (fleet.members().iter()).map(bind_member).collect()
}

fn bind_member(m: &Member) -> Result<Socket, (String, SocketAddr, io::Error)> {
    let bound = match m.autopilot {
        Autopilot::Px4 => std::net::TcpListener::bind(m.listen).map(Socket::Px4),
        Autopilot::Ardupilot => std::net::UdpSocket::bind(m.listen).map(Socket::ArduPilot),
    };
    bound.map_err(|e| (m.name.clone(), m.listen, e))
}

/// What the poll read, in the order it was read.
#[derive(Debug)]
pub enum Event {
    Px4Connected {
        i: usize,
        peer: SocketAddr,
    },
    Px4Bytes {
        i: usize,
        bytes: Vec<u8>,
    },
    Px4Closed {
        i: usize,
        why: String,
    },
    Datagram {
        i: usize,
        bytes: Vec<u8>,
        from: SocketAddr,
    },
}

/// Bytes a PX4 that does not read may have queued beyond its socket's buffer; more are dropped
/// whole (a stalled PX4 must not grow the fleet's memory; it is silenced after the timeout).
const PENDING_CAP: usize = 256 * 1024;

/// One read's buffer: larger than what a PX4 sends per step many times over.
const READ_BUFFER: usize = 64 * 1024;

#[derive(Debug)]
struct Connection {
    stream: TcpStream,
    /// Bytes accepted for this PX4 that its socket had no room for yet.
    pending: Vec<u8>,
    dropped: u64,
}

#[derive(Debug)]
enum Port {
    Px4 {
        listener: TcpListener,
        connection: Option<Connection>,
    },
    ArduPilot(UdpSocket),
}

impl Port {
    /// PX4's current connection, if this is a PX4's port and one is connected.
    fn connection(&self) -> Option<&Connection> {
        match self {
            Port::Px4 { connection, .. } => connection.as_ref(),
            Port::ArduPilot(_) => None,
        }
    }

    fn connection_mut(&mut self) -> Option<&mut Connection> {
        match self {
            Port::Px4 { connection, .. } => connection.as_mut(),
            Port::ArduPilot(_) => None,
        }
    }
}

/// Autopilot i's port has token 2i, its PX4 connection 2i + 1.
fn port_token(i: usize) -> Token {
    Token(2 * i)
}

fn connection_token(i: usize) -> Token {
    Token(2 * i + 1)
}

#[derive(Debug)]
pub struct Sockets {
    poll: Poll,
    events: Events,
    ports: Vec<Port>,
    buf: Vec<u8>,
    /// PX4s with bytes queued since the last `send_queued`.
    queued: Vec<usize>,
    uring: Uring,
}

impl Sockets {
    pub fn new(sockets: Vec<Socket>) -> io::Result<Self> {
        let poll = Poll::new()?;
        let mut ports = Vec::with_capacity(sockets.len());
        for (i, socket) in sockets.into_iter().enumerate() {
            let port = match socket {
                Socket::Px4(listener) => {
                    listener.set_nonblocking(true)?;
                    let mut listener = TcpListener::from_std(listener);
                    poll.registry()
                        .register(&mut listener, port_token(i), Interest::READABLE)?;
                    Port::Px4 {
                        listener,
                        connection: None,
                    }
                }
                Socket::ArduPilot(socket) => {
                    socket.set_nonblocking(true)?;
                    let mut socket = UdpSocket::from_std(socket);
                    poll.registry()
                        .register(&mut socket, port_token(i), Interest::READABLE)?;
                    Port::ArduPilot(socket)
                }
            };
            ports.push(port);
        }
        Ok(Sockets {
            poll,
            events: Events::with_capacity(2 * ports.len().max(1)),
            uring: Uring::new(ports.len()),
            ports,
            buf: vec![0; READ_BUFFER],
            queued: Vec::new(),
        })
    }

    /// Waits up to `timeout` for any socket — or, while the world waits for the PX4s of
    /// `awaited` only, for all of them to answer — then reads everything that is there into
    /// `out`. Must be called on the thread that made `self` (its io_uring).
    pub fn poll(
        &mut self,
        timeout: Duration,
        awaited: &[usize],
        out: &mut Vec<Event>,
    ) -> io::Result<()> {
        let px4s: Option<Vec<(usize, RawFd)>> = (awaited.iter())
            .map(|&i| Some((i, self.ports[i].connection()?.stream.as_raw_fd())))
            .collect();
        let timeout = match px4s {
            Some(fds) if !fds.is_empty() && self.uring.wait_readable(&fds, timeout).is_some() => {
                Duration::ZERO
            }
            _ => timeout,
        };
        match self.poll.poll(&mut self.events, Some(timeout)) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::Interrupted => return Ok(()),
            Err(e) => return Err(e),
        }
        // Taken out while its events are handled (they need `self`), put back after.
        let events = std::mem::replace(&mut self.events, Events::with_capacity(0));
        for event in &events {
            let i = event.token().0 / 2;
            if event.token().0 % 2 == 0 {
                self.read_port(i, out);
            } else {
                if event.is_writable() {
                    self.send_pending(i, out);
                }
                self.read_connection(i, out);
            }
        }
        self.events = events;
        Ok(())
    }

    /// Accepts PX4 i's connection, or reads ArduPilot i's datagrams, until none is left.
    fn read_port(&mut self, i: usize, out: &mut Vec<Event>) {
        let registry = self.poll.registry();
        match &mut self.ports[i] {
            Port::Px4 {
                listener,
                connection,
            } => loop {
                let (mut stream, peer) = match listener.accept() {
                    Ok(accepted) => accepted,
                    Err(e) if is_retry(e.kind()) => return,
                    Err(e) => {
                        tracing::warn!(error = %e, "accepting PX4 {i}'s connection failed");
                        return;
                    }
                };
                if connection.is_some() {
                    let port = listener.local_addr().map(|a| a.port()).unwrap_or(0);
                    tracing::warn!(%peer, port, "refused a second PX4 connection: one PX4 is already connected on this port");
                    continue;
                }
                let registered = stream.set_nodelay(true).and_then(|()| {
                    let interest = Interest::READABLE | Interest::WRITABLE;
                    registry.register(&mut stream, connection_token(i), interest)
                });
                if let Err(e) = registered {
                    tracing::warn!(%peer, error = %e, "PX4 connection unusable: dropped");
                    continue;
                }
                *connection = Some(Connection {
                    stream,
                    pending: Vec::new(),
                    dropped: 0,
                });
                out.push(Event::Px4Connected { i, peer });
            },
            Port::ArduPilot(socket) => loop {
                match socket.recv_from(&mut self.buf) {
                    Ok((n, from)) => out.push(Event::Datagram {
                        i,
                        bytes: self.buf[..n].to_vec(),
                        from,
                    }),
                    Err(e) if e.kind() == io::ErrorKind::WouldBlock => return,
                    Err(e) if is_retry(e.kind()) => {}
                    // E.g. an ICMP error reported on the socket: it is taken, the reads go on.
                    Err(e) => tracing::debug!(error = %e, "ArduPilot {i}: receive failed"),
                }
            },
        }
    }

    /// Reads PX4 i's connection until it is drained; a closed or failed one is dropped.
    fn read_connection(&mut self, i: usize, out: &mut Vec<Event>) {
        let Some(c) = self.ports[i].connection_mut() else {
            return;
        };
        let why = loop {
            match c.stream.read(&mut self.buf) {
                Ok(0) => break "connection closed".to_string(),
                Ok(n) => {
                    out.push(Event::Px4Bytes {
                        i,
                        bytes: self.buf[..n].to_vec(),
                    });
                    // A read shorter than the buffer drained the socket: bytes that arrive
                    // after it raise a new readiness event, so the read that would say
                    // WouldBlock (one more system call per PX4 step) is skipped.
                    if n < self.buf.len() {
                        return;
                    }
                }
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => return,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => break format!("read failed: {e}"),
            }
        };
        self.close(i, why, out);
    }

    fn close(&mut self, i: usize, why: String, out: &mut Vec<Event>) {
        if let Port::Px4 { connection, .. } = &mut self.ports[i] {
            if let Some(mut c) = connection.take() {
                self.uring.disarm(i);
                // Dropping the stream closes it, which also removes it from the poll.
                let _ = self.poll.registry().deregister(&mut c.stream);
                out.push(Event::Px4Closed { i, why });
            }
        }
    }

    /// Queues `bytes` for PX4 i (nothing if it is not connected) until [`Self::send_queued`].
    /// What its socket has no room for waits for the socket to drain, up to PENDING_CAP;
    /// beyond that whole writes drop.
    pub fn queue_px4(&mut self, i: usize, bytes: &[u8], name: &str) {
        let Some(c) = self.ports[i].connection_mut() else {
            return;
        };
        if c.pending.len() + bytes.len() > PENDING_CAP {
            if c.dropped == 0 {
                tracing::warn!(vehicle = %name, "PX4 does not read its socket: sensor bytes dropped");
            }
            c.dropped += 1;
            return;
        }
        c.pending.extend_from_slice(bytes);
        if !self.queued.contains(&i) {
            self.queued.push(i);
        }
    }

    /// Sends what was queued, to every PX4 at once where it can ([`Uring::send`]); a connection
    /// a write fails on is closed (a `Px4Closed` in `out`).
    pub fn send_queued(&mut self, out: &mut Vec<Event>) {
        let mut queued = std::mem::take(&mut self.queued);
        let sent = if queued.len() >= 2 {
            let items: Vec<Item<'_>> = (queued.iter())
                .filter_map(|&i| self.ports[i].connection())
                .map(|c| (c.stream.as_raw_fd(), &c.pending[..]))
                .collect();
            if items.len() == queued.len() {
                self.uring.send(&items)
            } else {
                None
            }
        } else {
            None
        };
        match sent {
            Some(results) => {
                for (&i, result) in queued.iter().zip(results) {
                    self.sent(i, result, out);
                }
            }
            None => {
                for &i in &queued {
                    self.send_pending(i, out);
                }
            }
        }
        queued.clear();
        self.queued = queued;
    }

    /// What a batched write to PX4 i did: the rest goes as `send_pending` sends it.
    fn sent(&mut self, i: usize, result: io::Result<usize>, out: &mut Vec<Event>) {
        let Some(c) = self.ports[i].connection_mut() else {
            return;
        };
        match result {
            Ok(n) => {
                c.pending.drain(..n.min(c.pending.len()));
                self.send_pending(i, out);
            }
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
            Err(e) => self.close(i, format!("write failed: {e}"), out),
        }
    }

    /// Writes PX4 i's pending bytes until they are gone or its socket is full.
    fn send_pending(&mut self, i: usize, out: &mut Vec<Event>) {
        let Some(c) = self.ports[i].connection_mut() else {
            return;
        };
        let mut sent = 0;
        let failed = loop {
            if sent == c.pending.len() {
                break None;
            }
            match c.stream.write(&c.pending[sent..]) {
                Ok(0) => break Some("write wrote nothing".to_string()),
                Ok(n) => sent += n,
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => break None,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => break Some(format!("write failed: {e}")),
            }
        };
        c.pending.drain(..sent);
        if let Some(why) = failed {
            self.close(i, why, out);
        }
    }

    /// Sends ArduPilot i one datagram.
    pub fn send_ardupilot(&self, i: usize, bytes: &[u8], to: SocketAddr) -> io::Result<()> {
        match &self.ports[i] {
            Port::ArduPilot(socket) => socket.send_to(bytes, to).map(|_| ()),
            Port::Px4 { .. } => Ok(()),
        }
    }
}
