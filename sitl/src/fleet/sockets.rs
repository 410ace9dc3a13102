//! Every autopilot's socket on one `mio` poll, read by the fleet thread itself: a PX4's TCP
//! port (one connection at a time; a second is refused while one is active) and an
//! ArduPilot's UDP port. One wake-up reads every socket that has bytes, so a world step
//! costs one wake-up per batch of answers, not a thread switch per message each way.
//!
//! Writes never block the fleet: what a PX4's socket does not take at once waits in that
//! connection's queue (sent when the socket is writable again, dropped beyond
//! [`QUEUE_LIMIT`]).

use mio::net::{TcpListener, TcpStream, UdpSocket};
use mio::{Events, Interest, Poll, Token};
use std::io::{self, Read, Write};
use std::net::SocketAddr;
use std::ops::Range;
use std::time::Duration;

/// An autopilot's socket, bound before the SITL says it is ready.
#[derive(Debug)]
pub enum Socket {
    Px4(std::net::TcpListener),
    ArduPilot(std::net::UdpSocket),
}

/// What a poll read, in the order read; bytes are a range of [`Sockets::bytes`].
#[derive(Debug, Clone, PartialEq)]
pub enum Received {
    Px4Connected {
        i: usize,
        peer: SocketAddr,
    },
    Px4Bytes {
        i: usize,
        bytes: Range<usize>,
    },
    Px4Closed {
        i: usize,
        why: String,
    },
    Datagram {
        i: usize,
        bytes: Range<usize>,
        from: SocketAddr,
    },
}

/// Bytes a PX4 connection may hold unsent before more are dropped (a PX4 that stopped
/// reading; the timeout silences it).
const QUEUE_LIMIT: usize = 1 << 20;
/// A wait at least this long that ends with no event is followed by a [`Sockets::sweep`].
const SWEEP_AFTER: Duration = Duration::from_millis(10);
/// Largest read of one socket at a time.
const READ_CHUNK: usize = 16_384;

/// A PX4's connection and the bytes its socket has not taken yet.
#[derive(Debug)]
struct Connection {
    stream: TcpStream,
    queued: Vec<u8>,
    /// Bytes dropped since the queue was last full (a warning per overflow).
    dropped: usize,
    /// Whether the poll is asked for this socket's writable events (bytes are queued).
    awaits_writable: bool,
}

#[derive(Debug)]
enum Port {
    Px4 {
        listener: TcpListener,
        connection: Option<Connection>,
    },
    ArduPilot(UdpSocket),
}

/// The fleet's sockets. Tokens: 2i for autopilot i's port, 2i + 1 for its PX4 connection.
#[derive(Debug)]
pub struct Sockets {
    poll: Poll,
    events: Events,
    ports: Vec<Port>,
    received: Vec<Received>,
    bytes: Vec<u8>,
    /// The last poll's events (token, writable), kept to spare an allocation per poll.
    ready: Vec<(Token, bool)>,
    /// Quiet waits after which a [`Sockets::sweep`] found bytes.
    pub unannounced: u64,
}

fn port_token(i: usize) -> Token {
    Token(2 * i)
}

fn connection_token(i: usize) -> Token {
    Token(2 * i + 1)
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
            events: Events::with_capacity(256),
            ports,
            received: Vec::new(),
            bytes: Vec::new(),
            ready: Vec::new(),
            unannounced: 0,
        })
    }

    /// The bytes the last [`Sockets::poll`]'s `Received` ranges point into.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// Waits at most `timeout` for any socket, then reads every socket that is ready until
    /// it has nothing more. Returns what was read (empty on a timeout).
    pub fn poll(&mut self, timeout: Duration) -> &[Received] {
        self.received.clear();
        self.bytes.clear();
        // epoll waits whole milliseconds (mio rounds up): a shorter wait (the free clock's
        // 400 µs steps before lockstep) looks, then sleeps the rest and looks again.
        let polled = if timeout >= Duration::from_millis(1) {
            self.poll.poll(&mut self.events, Some(timeout))
        } else {
            match self.poll.poll(&mut self.events, Some(Duration::ZERO)) {
                Ok(()) if self.events.is_empty() => {
                    std::thread::sleep(timeout);
                    self.poll.poll(&mut self.events, Some(Duration::ZERO))
                }
                polled => polled,
            }
        };
        if let Err(e) = polled {
            if e.kind() != io::ErrorKind::Interrupted {
                tracing::warn!(error = %e, "polling the fleet's sockets failed");
            }
            return &self.received;
        }
        self.ready.clear();
        (self.ready).extend(self.events.iter().map(|e| (e.token(), e.is_writable())));
        for k in 0..self.ready.len() {
            let (token, writable) = self.ready[k];
            let i = token.0 / 2;
            if token == port_token(i) {
                self.read_port(i);
            } else {
                if writable {
                    self.send_queued(i);
                }
                self.read_connection(i);
            }
        }
        if self.ready.is_empty() && timeout >= SWEEP_AFTER {
            self.sweep();
        }
        &self.received
    }

    /// After a quiet wait: reads every socket anyway. Edge-triggered readiness that went
    /// missing would otherwise leave an answer unread until the autopilot sends again
    /// (a PX4's next heartbeat: a second), stalling the whole fleet; counted and logged.
    fn sweep(&mut self) {
        for i in 0..self.ports.len() {
            match self.ports[i] {
                Port::Px4 { .. } => self.read_connection(i),
                Port::ArduPilot(_) => self.read_port(i),
            }
        }
        if !self.received.is_empty() {
            self.unannounced += 1;
            tracing::warn!(
                reads = self.received.len(),
                "read bytes that came without a readiness event"
            );
        }
    }

    fn read_port(&mut self, i: usize) {
        match &mut self.ports[i] {
            Port::Px4 { .. } => self.accept(i),
            Port::ArduPilot(socket) => loop {
                let start = self.bytes.len();
                self.bytes.resize(start + READ_CHUNK, 0);
                let got = socket.recv_from(&mut self.bytes[start..]);
                let n = *got.as_ref().map_or(&0, |(n, _)| n);
                self.bytes.truncate(start + n);
                match got {
                    Ok((n, from)) => self.received.push(Received::Datagram {
                        i,
                        bytes: start..start + n,
                        from,
                    }),
                    Err(e) if e.kind() == io::ErrorKind::WouldBlock => return,
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                    // E.g. an ICMP error reported on the socket: the loop goes on.
                    Err(e) => tracing::debug!(error = %e, "ArduPilot {i}: receive failed"),
                }
            },
        }
    }

    /// Every connection waiting on PX4 i's port: the first is taken unless one is active,
    /// the others refused (closed).
    fn accept(&mut self, i: usize) {
        let Port::Px4 {
            listener,
            connection,
        } = &mut self.ports[i]
        else {
            return;
        };
        loop {
            let (mut stream, peer) = match listener.accept() {
                Ok(accepted) => accepted,
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => return,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
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
                (self.poll.registry()).register(
                    &mut stream,
                    connection_token(i),
                    Interest::READABLE,
                )
            });
            if let Err(e) = registered {
                tracing::warn!(%peer, error = %e, "PX4 connection unusable: dropped");
                continue;
            }
            *connection = Some(Connection {
                stream,
                queued: Vec::new(),
                dropped: 0,
                awaits_writable: false,
            });
            self.received.push(Received::Px4Connected { i, peer });
            // Bytes that came with the connection are read on its own readiness event.
        }
    }

    /// PX4 i's stream until it has nothing more, or its end.
    fn read_connection(&mut self, i: usize) {
        let Port::Px4 {
            connection: Some(c),
            ..
        } = &mut self.ports[i]
        else {
            return;
        };
        let why = loop {
            let start = self.bytes.len();
            self.bytes.resize(start + READ_CHUNK, 0);
            let got = c.stream.read(&mut self.bytes[start..]);
            self.bytes.truncate(start + *got.as_ref().unwrap_or(&0));
            match got {
                Ok(0) => break "connection closed".to_string(),
                Ok(n) => self.received.push(Received::Px4Bytes {
                    i,
                    bytes: start..start + n,
                }),
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => return,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => break format!("read failed: {e}"),
            }
        };
        self.close(i);
        self.received.push(Received::Px4Closed { i, why });
    }

    fn close(&mut self, i: usize) {
        if let Port::Px4 { connection, .. } = &mut self.ports[i] {
            if let Some(mut c) = connection.take() {
                let _ = self.poll.registry().deregister(&mut c.stream);
            }
        }
    }

    /// Whether PX4 i is connected.
    pub fn is_connected(&self, i: usize) -> bool {
        matches!(
            &self.ports[i],
            Port::Px4 {
                connection: Some(_),
                ..
            }
        )
    }

    /// `bytes` to PX4 i's connection (nothing when it has none): written now as far as the
    /// socket takes them, the rest queued.
    pub fn send_px4(&mut self, i: usize, bytes: &[u8], name: &str) {
        let Port::Px4 {
            connection: Some(c),
            ..
        } = &mut self.ports[i]
        else {
            return;
        };
        if c.queued.len() + bytes.len() > QUEUE_LIMIT {
            if c.dropped == 0 {
                tracing::warn!(vehicle = %name, "PX4 does not read its stream: bytes dropped");
            }
            c.dropped += bytes.len();
            return;
        }
        c.dropped = 0;
        c.queued.extend_from_slice(bytes);
        self.send_queued(i);
    }

    /// PX4 i's queue to its socket, as far as it takes it; asks for a writable event when
    /// bytes are left.
    fn send_queued(&mut self, i: usize) {
        let Port::Px4 {
            connection: Some(c),
            ..
        } = &mut self.ports[i]
        else {
            return;
        };
        let mut sent = 0;
        while sent < c.queued.len() {
            match c.stream.write(&c.queued[sent..]) {
                Ok(0) => break,
                Ok(n) => sent += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => break,
                Err(e) => {
                    // The read side reports the end of the connection.
                    tracing::warn!(error = %e, "write to PX4 {i} failed: bytes dropped");
                    sent = c.queued.len();
                }
            }
        }
        c.queued.drain(..sent);
        let awaits_writable = !c.queued.is_empty();
        if awaits_writable != c.awaits_writable {
            let interest = if awaits_writable {
                Interest::READABLE | Interest::WRITABLE
            } else {
                Interest::READABLE
            };
            let token = connection_token(i);
            match self
                .poll
                .registry()
                .reregister(&mut c.stream, token, interest)
            {
                Ok(()) => c.awaits_writable = awaits_writable,
                Err(e) => {
                    tracing::warn!(error = %e, "PX4 {i}'s connection: poll interest not changed")
                }
            }
        }
    }

    /// `bytes` to ArduPilot i at `to` (a datagram the socket cannot take now is dropped, as
    /// the network would).
    pub fn send_ardupilot(&self, i: usize, bytes: &[u8], to: SocketAddr) -> io::Result<()> {
        match &self.ports[i] {
            Port::ArduPilot(socket) => socket.send_to(bytes, to).map(|_| ()),
            Port::Px4 { .. } => Ok(()),
        }
    }
}
