//! The floor for benchmarks/sitl_roundtrip.py: a UDP server on the same tokio set-up as the
//! SITL (one thread, `recv_from` / `send_to`) that answers every datagram with a canned reply.
//! A datagram starting with `SET ` replaces the canned reply with the rest of its bytes.
//! Prints `udp-echo ready listen=<addr>` on stdout; stops on SIGTERM or SIGINT.

use tokio::net::UdpSocket;
use tokio::signal::unix::{SignalKind, signal};

fn main() -> std::io::Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    runtime.block_on(async {
        let socket = UdpSocket::bind("127.0.0.1:0").await?;
        let mut terminate = signal(SignalKind::terminate())?;
        let mut interrupt = signal(SignalKind::interrupt())?;
        println!("udp-echo ready listen={}", socket.local_addr()?);
        let mut buf = vec![0u8; 65_536];
        let mut reply: Vec<u8> = Vec::new();
        loop {
            tokio::select! {
                _ = terminate.recv() => return Ok(()),
                _ = interrupt.recv() => return Ok(()),
                r = socket.recv_from(&mut buf) => {
                    let (n, from) = r?;
                    if let Some(canned) = buf[..n].strip_prefix(b"SET ") {
                        reply = canned.to_vec();
                        socket.send_to(b"OK", from).await?;
                    } else {
                        socket.send_to(&reply, from).await?;
                    }
                }
            }
        }
    })
}
