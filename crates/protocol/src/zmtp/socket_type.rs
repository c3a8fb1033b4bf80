//! The ZeroMQ socket types a `READY` command may name, and which may talk to which.

use std::fmt;

/// A ZeroMQ socket type, as named in the `Socket-Type` property of `READY` (RFC 37).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SocketType {
    /// `REQ`: what the CoppeliaSim client uses.
    Req,
    /// `REP`.
    Rep,
    /// `DEALER`.
    Dealer,
    /// `ROUTER`: what gantry serves.
    Router,
    /// `PUB`.
    Pub,
    /// `SUB`.
    Sub,
    /// `XPUB`.
    XPub,
    /// `XSUB`.
    XSub,
    /// `PUSH`.
    Push,
    /// `PULL`.
    Pull,
    /// `PAIR`.
    Pair,
}

impl SocketType {
    pub(super) const ALL: [SocketType; 11] = [
        Self::Req,
        Self::Rep,
        Self::Dealer,
        Self::Router,
        Self::Pub,
        Self::Sub,
        Self::XPub,
        Self::XSub,
        Self::Push,
        Self::Pull,
        Self::Pair,
    ];

    /// The name on the wire.
    pub fn name(self) -> &'static str {
        match self {
            Self::Req => "REQ",
            Self::Rep => "REP",
            Self::Dealer => "DEALER",
            Self::Router => "ROUTER",
            Self::Pub => "PUB",
            Self::Sub => "SUB",
            Self::XPub => "XPUB",
            Self::XSub => "XSUB",
            Self::Push => "PUSH",
            Self::Pull => "PULL",
            Self::Pair => "PAIR",
        }
    }

    /// The socket type named `name` (exactly, as libzmq compares it).
    pub fn from_name(name: &[u8]) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name().as_bytes() == name)
    }

    /// Whether a socket of this type may talk to a `peer` socket (the table of RFC 28
    /// and RFC 29, which libzmq enforces).
    pub fn accepts(self, peer: SocketType) -> bool {
        use SocketType::*;
        match self {
            Req => matches!(peer, Rep | Router),
            Rep => matches!(peer, Req | Dealer),
            Dealer => matches!(peer, Rep | Dealer | Router),
            Router => matches!(peer, Req | Dealer | Router),
            Pub | XPub => matches!(peer, Sub | XSub),
            Sub | XSub => matches!(peer, Pub | XPub),
            Push => peer == Pull,
            Pull => peer == Push,
            Pair => peer == Pair,
        }
    }
}

impl fmt::Display for SocketType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
