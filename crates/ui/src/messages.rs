//! CoppeliaSim's simulator messages (`sim.getSimulatorMessage`): events of the user
//! interface, here the keys pressed in the viewer, that scripts poll for; and the
//! keyboard modifiers held now (`simUI.getKeyboardModifiers`).
//!
//! As in CoppeliaSim each reader has its own queue, so two scripts that poll both see
//! every key: one log of recent messages, and a position in it per reader (a script's
//! object, or `None` for remote clients). The log keeps the last [`MESSAGE_CAPACITY`]
//! messages; a reader that falls further behind loses the oldest.

use std::collections::{HashMap, VecDeque};

use gantry_scene::Handle;

/// Messages kept for readers that have not read them yet.
pub const MESSAGE_CAPACITY: usize = 256;

/// `sim.message_keypress`: `auxiliaryData` holds the key code and the modifiers.
pub const MESSAGE_KEYPRESS: i64 = 6;

/// CoppeliaSim's codes of the keys that are not characters (`auxiliaryData[1]`).
pub mod keys {
    /// Arrow up.
    pub const UP: i64 = 2007;
    /// Arrow down.
    pub const DOWN: i64 = 2008;
    /// Arrow left.
    pub const LEFT: i64 = 2009;
    /// Arrow right.
    pub const RIGHT: i64 = 2010;
}

/// One message: its kind and CoppeliaSim's four auxiliary integers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SimulatorMessage {
    /// `sim.message_*`.
    pub kind: i64,
    /// `auxiliaryData` (for a key: code, modifiers (bit 0 ctrl, bit 1 shift), 0, 0).
    pub aux: [i64; 4],
}

/// The modifier keys held down (`simUI.getKeyboardModifiers`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct KeyboardModifiers {
    /// Ctrl (Cmd on macOS in CoppeliaSim's Qt).
    pub control: bool,
    /// Shift.
    pub shift: bool,
    /// Alt.
    pub alt: bool,
}

/// The recent messages and where each reader is.
#[derive(Debug, Clone, Default)]
pub struct SimulatorMessages {
    /// The modifiers held now, as the front end last reported them; none held when no
    /// front end reports any (headless runs).
    pub modifiers: KeyboardModifiers,
    log: VecDeque<SimulatorMessage>,
    /// Sequence number of the oldest message in `log`.
    first: u64,
    /// Sequence number of the next message each reader gets.
    readers: HashMap<Option<Handle>, u64>,
}

impl SimulatorMessages {
    /// Posts a message for every reader.
    pub fn post(&mut self, message: SimulatorMessage) {
        if self.log.len() == MESSAGE_CAPACITY {
            self.log.pop_front();
            self.first += 1;
        }
        self.log.push_back(message);
    }

    /// A key press (`sim.message_keypress`): `code` is the character's code or one of
    /// [`keys`]; `modifiers` bit 0 is ctrl, bit 1 shift.
    pub fn post_key(&mut self, code: i64, modifiers: i64) {
        self.post(SimulatorMessage {
            kind: MESSAGE_KEYPRESS,
            aux: [code, modifiers & 3, 0, 0],
        });
    }

    /// The next message for `reader`, which then moves past it; `None` when it has
    /// read them all. A reader's first read starts at the oldest message kept.
    pub fn next(&mut self, reader: Option<Handle>) -> Option<SimulatorMessage> {
        let end = self.first + self.log.len() as u64;
        let at = self.readers.entry(reader).or_insert(self.first);
        let at_now = (*at).max(self.first);
        if at_now >= end {
            *at = end;
            return None;
        }
        *at = at_now + 1;
        self.log.get((at_now - self.first) as usize).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_reader_gets_every_message_once() {
        let mut m = SimulatorMessages::default();
        m.post_key(keys::UP, 0);
        m.post_key(i64::from(b'a'), 2);
        for reader in [Some(3), None] {
            assert_eq!(m.next(reader).map(|x| x.aux[0]), Some(keys::UP));
            assert_eq!(m.next(reader).map(|x| x.aux), Some([97, 2, 0, 0]));
            assert_eq!(m.next(reader), None);
        }
        m.post_key(keys::LEFT, 7);
        assert_eq!(m.next(Some(3)).map(|x| x.aux), Some([keys::LEFT, 3, 0, 0]));
        assert_eq!(m.next(Some(3)), None);
    }

    #[test]
    fn a_slow_reader_loses_the_oldest_only() {
        let mut m = SimulatorMessages::default();
        for k in 0..(MESSAGE_CAPACITY as i64 + 10) {
            m.post_key(k, 0);
        }
        assert_eq!(m.next(None).map(|x| x.aux[0]), Some(10));
        let mut n = 1;
        while m.next(None).is_some() {
            n += 1;
        }
        assert_eq!(n, MESSAGE_CAPACITY);
    }
}
