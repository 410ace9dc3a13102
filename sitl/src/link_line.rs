//! The link faults (`link_loss`, `link_delay`, core `faults::LinkCondition`) on a lockstep
//! link whose answers are whole byte strings: the lockstep task link's replies and
//! ArduPilot's JSON frames. A lockstep link carries the simulation's tick as well as its
//! data, and a tick that never came would stall both sides for good, so a link fault loses
//! or delays the *data*, never the tick: every command is still answered, with
//!
//! - a loss: the last answer that got through again (nothing new arrives; the other side's
//!   clock, which follows the answers' timestamps, stands still until the link is back and
//!   then jumps by the time lost);
//! - a delay `d`: the newest answer at least `d` old (until one is that old, the last one
//!   delivered), so the other side sees the world `d` late;
//! - a clear link: the fresh answer.
//!
//! The first answer always gets through (there is nothing older to repeat).

use flyloop_core::faults::LinkCondition;
use std::collections::VecDeque;

/// Answers waiting on a delayed link and the last one delivered.
#[derive(Debug, Clone)]
pub struct LinkLine<T> {
    /// Answers not yet delivered: (time made, µs; answer).
    queue: VecDeque<(u64, T)>,
    delivered: Option<T>,
}

impl<T> Default for LinkLine<T> {
    fn default() -> Self {
        LinkLine {
            queue: VecDeque::new(),
            delivered: None,
        }
    }
}

/// The replies of the lockstep task link and ArduPilot's JSON frames.
pub type ReplyLine = LinkLine<Vec<u8>>;

impl<T: Clone> LinkLine<T> {
    /// What the other side gets for the answer `fresh`, made at `time_us`, while the link is
    /// in `link`, and whether it is a new one (false: the last one again).
    pub fn pass_new(&mut self, time_us: u64, fresh: T, link: LinkCondition) -> (&T, bool) {
        let mut new = false;
        if link.lost {
            self.queue.clear();
        } else if link.delay > 0.0 {
            let delay_us = (link.delay * 1e6).round() as u64;
            self.queue.push_back((time_us, fresh.clone()));
            while let Some((made, _)) = self.queue.front() {
                if made.saturating_add(delay_us) > time_us {
                    break;
                }
                self.delivered = self.queue.pop_front().map(|(_, a)| a);
                new = true;
            }
        } else {
            self.queue.clear();
            self.delivered = Some(fresh.clone());
            new = true;
        }
        let first = self.delivered.is_none();
        let delivered = self.delivered.get_or_insert(fresh);
        (delivered, new || first)
    }

    /// A new episode or connection: nothing queued, nothing delivered.
    pub fn clear(&mut self) {
        self.queue.clear();
        self.delivered = None;
    }
}

impl ReplyLine {
    /// [`LinkLine::pass_new`] for a byte string.
    pub fn pass(&mut self, time_us: u64, fresh: &[u8], link: LinkCondition) -> &[u8] {
        self.pass_new(time_us, fresh.to_vec(), link).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CLEAR: LinkCondition = LinkCondition {
        lost: false,
        delay: 0.0,
    };

    #[test]
    fn a_loss_repeats_the_last_answer_and_a_delay_delivers_old_ones() {
        let mut line = ReplyLine::default();
        let lost = LinkCondition {
            lost: true,
            ..CLEAR
        };
        let late = LinkCondition {
            delay: 0.02,
            ..CLEAR
        };
        assert_eq!(line.pass(10_000, b"a", CLEAR), b"a");
        assert_eq!(line.pass(20_000, b"b", lost), b"a");
        assert_eq!(line.pass(30_000, b"c", lost), b"a");
        assert_eq!(line.pass(40_000, b"d", CLEAR), b"d");
        // 20 ms late: the last delivered until an answer is 20 ms old, then each 20 ms old.
        assert_eq!(line.pass(50_000, b"e", late), b"d");
        assert_eq!(line.pass(60_000, b"f", late), b"d");
        assert_eq!(line.pass(70_000, b"g", late), b"e");
        assert_eq!(line.pass(80_000, b"h", late), b"f");
        assert_eq!(line.pass(90_000, b"i", CLEAR), b"i");
        line.clear();
        assert_eq!(
            line.pass(0, b"j", lost),
            b"j",
            "the first answer gets through"
        );
    }
}
