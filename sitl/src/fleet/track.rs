//! The fleet's ground-truth track (`--track FILE` in fleet mode): the columns of the
//! single-vehicle track (docs/sitl.md, [`crate::track`]) after `vehicle,sysid`, a row per
//! vehicle every `--track-interval-us` of world time, the vehicles in the fleet's (name)
//! order, the `faults` column each vehicle's own events. `connection` counts its autopilot's connections (0: none yet, 1: the first,
//! 2 after a reconnect or restart, …); a vehicle with fewer rotors than the fleet's most
//! leaves the last motor columns empty.

use super::Fleet;
use crate::track::{fault_event, state_header, write_state};
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// The CSV header line of a fleet whose vehicles have at most `rotors` rotors.
pub fn header(rotors: usize) -> String {
    format!("vehicle,sysid,connection,time_us,{}", state_header(rotors))
}

/// A fleet's track file being written.
#[derive(Debug)]
pub struct FleetTrack {
    out: BufWriter<File>,
    next_us: u64,
    interval_us: u64,
    rotors: usize,
    /// Per vehicle, the fault events already written (of its `fault_log`).
    written: Vec<usize>,
}

impl FleetTrack {
    /// Creates (truncates) `path` and writes the header for `fleet`; rows every
    /// `interval_us` of world time.
    pub fn create(path: &Path, interval_us: u64, fleet: &Fleet) -> io::Result<Self> {
        let rotors = (fleet.members().iter())
            .map(|m| m.rotors)
            .max()
            .unwrap_or(0);
        let mut out = BufWriter::new(File::create(path)?);
        writeln!(out, "{}", header(rotors))?;
        Ok(FleetTrack {
            out,
            next_us: 0,
            interval_us,
            rotors,
            written: vec![0; fleet.members().len()],
        })
    }

    /// A row per vehicle at the world's time when one is due.
    pub fn record(&mut self, fleet: &Fleet) -> io::Result<()> {
        let time_us = fleet.lockstep().now_us();
        if time_us < self.next_us {
            return Ok(());
        }
        self.next_us = time_us + self.interval_us;
        for (i, m) in fleet.members().iter().enumerate() {
            write!(
                self.out,
                "{},{},{},{time_us}",
                m.name, m.sysid, m.connections
            )?;
            let log = m.fault_log.get(self.written[i]..).unwrap_or_default();
            let events: Vec<String> = log.iter().map(fault_event).collect();
            self.written[i] = m.fault_log.len();
            write_state(
                &mut self.out,
                fleet.vehicle(i),
                self.rotors,
                &events.join(" "),
            )?;
        }
        Ok(())
    }

    /// Writes buffered rows out.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

#[cfg(test)]
mod tests;
