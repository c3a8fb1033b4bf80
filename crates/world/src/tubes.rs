//! Tubes: V-REP's pipes between scripts of one simulation (`sim.tubeOpen`). Two opens
//! with the same header and name are the two ends of one tube; what one end writes, the
//! other reads, in order. Old sensor models (gyroscope, accelerometer, laser scanners)
//! hand their readings to other scripts this way.
//!
//! Bounded: each end keeps at most its read buffer size of packets (the oldest go
//! first, as in CoppeliaSim), at most [`MAX_BUFFER`], and a packet is at most
//! [`MAX_PACKET`] bytes. Tubes belong to one run: they go with the simulation at stop.

use std::collections::{BTreeMap, VecDeque};

use crate::error::SimError;

/// Packets an end may hold, whatever the script asks for.
pub const MAX_BUFFER: usize = 10_000;
/// Largest packet, bytes (a 2048 x 2048 RGBA image).
pub const MAX_PACKET: usize = 16 << 20;

/// One end of a tube.
#[derive(Debug)]
struct End {
    /// `(header, name)`, as opened.
    key: (i64, String),
    /// The other end, once opened.
    peer: Option<i64>,
    /// Packets written by the other end, not read yet.
    inbox: VecDeque<Vec<u8>>,
    /// Read buffer size, packets.
    capacity: usize,
}

/// Every open tube end, by handle.
#[derive(Debug, Default)]
pub struct Tubes {
    ends: BTreeMap<i64, End>,
    next: i64,
}

/// What `sim.tubeStatus` reports of an end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TubeStatus {
    /// Whether the other end is open.
    pub connected: bool,
    /// Packets waiting to be read at this end.
    pub to_read: usize,
    /// Packets this end wrote that the other has not read yet.
    pub unread_by_peer: usize,
}

fn no_tube(h: i64) -> SimError {
    SimError::no_such_item(format!("tube {h} does not exist"))
}

impl Tubes {
    /// Opens an end: the other end of a tube of the same header and name that waits
    /// for one, or a new tube's first end. `capacity` packets are kept for reading (at
    /// least 1, at most [`MAX_BUFFER`]).
    pub fn open(&mut self, header: i64, name: &str, capacity: i64) -> i64 {
        self.next += 1;
        let h = self.next;
        let key = (header, name.to_owned());
        let waiting = self
            .ends
            .iter()
            .find(|(_, e)| e.peer.is_none() && e.key == key)
            .map(|(h, _)| *h);
        if let Some(w) = waiting
            && let Some(e) = self.ends.get_mut(&w)
        {
            e.peer = Some(h);
        }
        let capacity = usize::try_from(capacity).unwrap_or(1).clamp(1, MAX_BUFFER);
        self.ends.insert(
            h,
            End {
                key,
                peer: waiting,
                inbox: VecDeque::new(),
                capacity,
            },
        );
        h
    }

    /// Writes a packet to the other end: whether it went (false when no other end is
    /// open: the packet is dropped, as in CoppeliaSim).
    ///
    /// # Errors
    /// No such end, or a packet over [`MAX_PACKET`].
    pub fn write(&mut self, h: i64, data: Vec<u8>) -> Result<bool, SimError> {
        if data.len() > MAX_PACKET {
            return Err(SimError::bad_argument(format!(
                "argument 2: a packet of {} bytes is over the {MAX_PACKET}-byte limit",
                data.len()
            )));
        }
        let peer = self.ends.get(&h).ok_or_else(|| no_tube(h))?.peer;
        let Some(other) = peer.and_then(|p| self.ends.get_mut(&p)) else {
            return Ok(false);
        };
        if other.inbox.len() >= other.capacity {
            other.inbox.pop_front();
        }
        other.inbox.push_back(data);
        Ok(true)
    }

    /// The oldest packet waiting at this end, if any.
    ///
    /// # Errors
    /// No such end.
    pub fn read(&mut self, h: i64) -> Result<Option<Vec<u8>>, SimError> {
        Ok(self.ends.get_mut(&h).ok_or_else(|| no_tube(h))?.inbox.pop_front())
    }

    /// This end's state; `None` when there is no such end.
    pub fn status(&self, h: i64) -> Option<TubeStatus> {
        let e = self.ends.get(&h)?;
        let peer = e.peer.and_then(|p| self.ends.get(&p));
        Some(TubeStatus {
            connected: peer.is_some(),
            to_read: e.inbox.len(),
            unread_by_peer: peer.map_or(0, |p| p.inbox.len()),
        })
    }

    /// Closes an end; the other stays open, alone, with what it has not read.
    ///
    /// # Errors
    /// No such end.
    pub fn close(&mut self, h: i64) -> Result<(), SimError> {
        let e = self.ends.remove(&h).ok_or_else(|| no_tube(h))?;
        if let Some(p) = e.peer.and_then(|p| self.ends.get_mut(&p)) {
            p.peer = None;
            // Its tube is gone: a later open of the same name starts a new one rather
            // than joining this half-closed end.
            p.key.1.insert(0, '\0');
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_opens_of_one_name_are_the_two_ends() {
        let mut t = Tubes::default();
        let a = t.open(0, "gyro", 1);
        assert!(!t.write(a, b"lost".to_vec()).unwrap(), "no other end yet");
        let b = t.open(0, "gyro", 2);
        let other = t.open(1, "gyro", 1);
        assert_eq!(t.status(other).map(|s| s.connected), Some(false), "another header");
        for p in [b"1".to_vec(), b"2".to_vec(), b"3".to_vec()] {
            assert!(t.write(a, p).unwrap());
        }
        // b keeps 2 packets: the oldest went.
        assert_eq!(
            t.status(a),
            Some(TubeStatus {
                connected: true,
                to_read: 0,
                unread_by_peer: 2
            })
        );
        assert_eq!(t.read(b).unwrap(), Some(b"2".to_vec()));
        assert_eq!(t.read(b).unwrap(), Some(b"3".to_vec()));
        assert_eq!(t.read(b).unwrap(), None);
        t.write(b, b"back".to_vec()).unwrap();
        assert_eq!(t.read(a).unwrap(), Some(b"back".to_vec()), "full duplex");
        t.close(a).unwrap();
        assert_eq!(t.status(b).map(|s| s.connected), Some(false));
        assert!(!t.write(b, vec![1]).unwrap());
        let c = t.open(0, "gyro", 1);
        assert_eq!(
            t.status(c).map(|s| s.connected),
            Some(false),
            "a new tube, not the half-closed one"
        );
        assert!(t.read(a).is_err() && t.close(a).is_err() && t.status(a).is_none());
        assert!(t.write(c, vec![0; MAX_PACKET + 1]).is_err());
    }
}
