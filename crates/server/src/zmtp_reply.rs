//! The write side of one ZMTP connection, and replies written by whichever thread
//! finishes them.
//!
//! A request is answered on a oneshot channel by the simulation thread. Awaiting that
//! channel in the connection task would cost a thread wake-up per call (the task's
//! worker sleeps in the reactor, and waking it takes 50-100 µs on a loaded virtual
//! machine, most of a round trip of this protocol), and polling the channel to avoid
//! it keeps a core busy. Instead a [`ReplyHandle`] registers *itself* as the channel's
//! waker: when the simulation thread sends the answer, the waker runs right there, on
//! the simulation thread, encodes the reply and writes it to the socket with a
//! non-blocking write. Nothing is woken, nothing polls. The simulation thread pays for
//! one `write` call, which it would otherwise have spent handing the answer over.
//!
//! Only what the socket does not take at once (a reply larger than the kernel's send
//! buffer, or a peer that stops reading) is left in [`Outgoing`]'s buffer for the
//! connection task to flush when the socket is writable; then, and only then, is the
//! task woken.
//!
//! Replies are written whole, under one lock, so frames from different writers never
//! interleave. A connection serves one request at a time (see
//! [`Outgoing::ready_for_request`]), as its REQ client sends them, so at most one
//! reply is ever buffered per connection.

use std::future::Future;
use std::io;
use std::pin::Pin;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::task::{Context, Poll, Wake, Waker};

use bytes::{Buf, Bytes, BytesMut};
use gantry_protocol::zmtp;
use tokio::net::TcpStream;
use tokio::sync::{Notify, oneshot};
use tokio::task::Unconstrained;

/// The write side of one connection, shared by its connection task, the replies it
/// waits for (written from the simulation thread) and parked steps.
pub struct Outgoing {
    state: Mutex<OutState>,
    /// Wakes the connection task when it has something to do: bytes to flush, or the
    /// reply it holds its next request back for is written. Sent only then, so a
    /// reply written at once wakes nobody.
    wake: Notify,
}

struct OutState {
    /// The socket; `None` once the connection is closed (replies finishing later are
    /// dropped, and the socket is closed when the connection task lets go of it).
    stream: Option<Arc<TcpStream>>,
    /// Bytes the socket did not take yet, whole frames, in order.
    pending: BytesMut,
    /// A request is being served: its reply is not written yet.
    in_flight: bool,
    /// The connection task has the next request in hand and waits for `in_flight` to
    /// clear.
    waiting: bool,
}

/// Locks `m`, ignoring poisoning: every critical section here leaves the state whole
/// (they only push bytes or flip flags), so a panic elsewhere does not corrupt it.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Outgoing {
    /// The write side of `stream`.
    pub fn new(stream: Arc<TcpStream>) -> Arc<Self> {
        Arc::new(Self {
            state: Mutex::new(OutState {
                stream: Some(stream),
                pending: BytesMut::new(),
                in_flight: false,
                waiting: false,
            }),
            wake: Notify::new(),
        })
    }

    /// Writes `bytes` (whole frames: a greeting, a command) after anything pending.
    pub fn write(&self, bytes: &[u8]) {
        let mut st = lock(&self.state);
        let wake = st.push(bytes);
        drop(st);
        if wake {
            self.wake.notify_one();
        }
    }

    /// Writes the reply to the request being served: `envelope` (the frames that came
    /// before the request's payload, the empty delimiter for a REQ peer) then
    /// `payload`. The connection may then serve its next request.
    pub fn reply(&self, envelope: &[Bytes], payload: &[u8]) {
        let mut msg = Vec::with_capacity(
            envelope.iter().map(|f| f.len() + zmtp::MAX_HEADER_LEN).sum::<usize>()
                + payload.len()
                + zmtp::MAX_HEADER_LEN,
        );
        for f in envelope {
            zmtp::encode_frame(&mut msg, f, true);
        }
        zmtp::encode_frame(&mut msg, payload, false);
        let mut st = lock(&self.state);
        let mut wake = st.push(&msg);
        st.in_flight = false;
        wake |= std::mem::take(&mut st.waiting);
        drop(st);
        if wake {
            self.wake.notify_one();
        }
    }

    /// Replies with what arrives on `rx`, encoded by `encode` (`None` if the sender
    /// was dropped), as soon as it arrives, from the thread that sends it. Until then
    /// the connection serves no other request.
    pub fn reply_when_ready<T: Send + 'static>(
        self: &Arc<Self>,
        envelope: Vec<Bytes>,
        rx: oneshot::Receiver<T>,
        encode: fn(Option<T>) -> Vec<u8>,
    ) -> ReplyHandle {
        lock(&self.state).in_flight = true;
        let pending = Arc::new(PendingReply {
            out: self.clone(),
            slot: Mutex::new(Some(Waiting {
                // Unconstrained: tokio's cooperative budget would otherwise make the
                // poll below wake its waker from inside the poll.
                rx: tokio::task::unconstrained(rx),
                envelope,
                encode,
            })),
        });
        // Registers the waker, or replies now if the answer is already there.
        pending.poll();
        ReplyHandle { inner: pending }
    }

    /// Whether the connection may take its next request: nothing in flight and
    /// nothing left to flush. If not, the connection task is woken once it may, so
    /// ask only with a request (or part of one) in hand.
    pub fn ready_for_request(&self) -> bool {
        let mut st = lock(&self.state);
        let ready = !st.in_flight && st.pending.is_empty();
        st.waiting = !ready;
        ready
    }

    /// Whether bytes wait to be flushed.
    pub fn has_pending(&self) -> bool {
        !lock(&self.state).pending.is_empty()
    }

    /// Resolves when this side has something for the connection task to do (see
    /// the `wake` field); may resolve spuriously.
    pub async fn woken(&self) {
        self.wake.notified().await;
    }

    /// Writes what is pending, waiting for the socket to take it.
    ///
    /// # Errors
    /// The connection failed (or was closed); it is then closed for every writer.
    pub async fn flush(&self) -> io::Result<()> {
        loop {
            let stream = {
                let st = lock(&self.state);
                if st.pending.is_empty() {
                    return Ok(());
                }
                st.stream
                    .clone()
                    .ok_or_else(|| io::Error::from(io::ErrorKind::NotConnected))?
            };
            stream.writable().await?;
            let mut st = lock(&self.state);
            let OutState { stream, pending, .. } = &mut *st;
            let Some(stream) = stream else {
                return Err(io::ErrorKind::NotConnected.into());
            };
            match stream.try_write(pending) {
                Ok(n) => pending.advance(n),
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
                Err(e) => {
                    st.close();
                    return Err(e);
                }
            }
            if st.pending.is_empty() && std::mem::take(&mut st.waiting) {
                // The connection task is the caller: it looks again when this returns.
                drop(st);
                self.wake.notify_one();
            }
        }
    }

    /// Closes this side: nothing more is written, and the socket is released.
    pub fn close(&self) {
        lock(&self.state).close();
    }

    /// A reply will never come (its session ended): the connection may serve again.
    fn cancel_reply(&self) {
        let mut st = lock(&self.state);
        st.in_flight = false;
        let wake = std::mem::take(&mut st.waiting);
        drop(st);
        if wake {
            self.wake.notify_one();
        }
    }
}

impl OutState {
    /// Writes `bytes` now if nothing is pending and the socket takes them, else queues
    /// what is left. Returns whether the connection task must flush.
    fn push(&mut self, bytes: &[u8]) -> bool {
        let Some(stream) = &self.stream else {
            // Closed: the peer is gone, and so is whatever it was owed.
            return false;
        };
        let mut rest = bytes;
        if self.pending.is_empty() {
            match stream.try_write(rest) {
                Ok(n) => rest = &rest[n..],
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
                Err(e) => {
                    tracing::debug!("zmq remote API: reply not delivered: {e}");
                    self.close();
                    return false;
                }
            }
        }
        if rest.is_empty() {
            return false;
        }
        self.pending.extend_from_slice(rest);
        true
    }

    fn close(&mut self) {
        self.stream = None;
        self.pending = BytesMut::new();
    }
}

/// A reply waiting for the simulation thread's answer.
struct PendingReply<T> {
    out: Arc<Outgoing>,
    /// `None` once the reply is written or cancelled.
    slot: Mutex<Option<Waiting<T>>>,
}

struct Waiting<T> {
    rx: Unconstrained<oneshot::Receiver<T>>,
    envelope: Vec<Bytes>,
    encode: fn(Option<T>) -> Vec<u8>,
}

impl<T: Send + 'static> PendingReply<T> {
    /// Polls the answer with this reply as the waker; writes the reply once it is in.
    /// Runs on the connection task once, then on whatever thread completes the
    /// channel (the simulation thread, in practice).
    fn poll(self: &Arc<Self>) {
        let mut slot = lock(&self.slot);
        let Some(waiting) = slot.as_mut() else {
            return;
        };
        let waker = Waker::from(self.clone());
        let answer = match Pin::new(&mut waiting.rx).poll(&mut Context::from_waker(&waker)) {
            Poll::Pending => return,
            Poll::Ready(answer) => answer.ok(),
        };
        let Some(waiting) = slot.take() else { return };
        drop(slot);
        self.out.reply(&waiting.envelope, &(waiting.encode)(answer));
    }
}

impl<T: Send + 'static> Wake for PendingReply<T> {
    fn wake(self: Arc<Self>) {
        self.poll();
    }

    fn wake_by_ref(self: &Arc<Self>) {
        self.poll();
    }
}

/// What a session keeps of a reply it is owed (a parked `sim.step`).
trait Owed: Send + Sync {
    fn is_finished(&self) -> bool;
    fn abort(&self);
}

impl<T: Send + 'static> Owed for PendingReply<T> {
    fn is_finished(&self) -> bool {
        lock(&self.slot).is_none()
    }

    fn abort(&self) {
        // Dropping the receiver drops the waker registration with it.
        if lock(&self.slot).take().is_some() {
            self.out.cancel_reply();
        }
    }
}

/// A reply that will be written when its answer arrives (see the module docs).
pub struct ReplyHandle {
    inner: Arc<dyn Owed>,
}

impl ReplyHandle {
    /// Whether the reply is written (or cancelled).
    pub fn is_finished(&self) -> bool {
        self.inner.is_finished()
    }

    /// Cancels the reply: nothing will be written, and the connection serves its next
    /// request.
    pub fn abort(&self) {
        self.inner.abort();
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use tokio::io::AsyncReadExt;
    use tokio::net::TcpListener;

    use super::*;

    /// A connected pair: our side's [`Outgoing`], and the peer's stream.
    async fn pair() -> (Arc<Outgoing>, TcpStream) {
        let listener = TcpListener::bind("127.0.0.1:0").await.expect("bind");
        let peer = TcpStream::connect(listener.local_addr().expect("addr"))
            .await
            .expect("connect");
        let (ours, _) = listener.accept().await.expect("accept");
        (Outgoing::new(Arc::new(ours)), peer)
    }

    /// The frames of one reply with an empty delimiter.
    fn reply_bytes(payload: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        zmtp::encode_message(&mut out, &[b"", payload]);
        out
    }

    async fn read_exactly(peer: &mut TcpStream, n: usize) -> Vec<u8> {
        let mut got = vec![0; n];
        tokio::time::timeout(Duration::from_secs(10), peer.read_exact(&mut got))
            .await
            .expect("bytes within 10 s")
            .expect("read");
        got
    }

    fn encode(answer: Option<u32>) -> Vec<u8> {
        match answer {
            Some(n) => n.to_be_bytes().to_vec(),
            None => b"gone".to_vec(),
        }
    }

    #[tokio::test]
    async fn a_reply_is_written_by_the_thread_that_answers() {
        let (out, mut peer) = pair().await;
        let (tx, rx) = oneshot::channel();
        let handle = out.reply_when_ready(vec![Bytes::new()], rx, encode);
        assert!(!handle.is_finished());
        assert!(!out.ready_for_request(), "one request at a time");
        // The answer comes from a plain thread, as from the simulation thread; nothing
        // in this runtime is involved in writing it.
        std::thread::spawn(move || tx.send(7).expect("receiver alive"))
            .join()
            .expect("thread");
        assert!(handle.is_finished());
        assert!(!out.has_pending(), "written straight to the socket");
        assert!(out.ready_for_request());
        let expected = reply_bytes(&7u32.to_be_bytes());
        assert_eq!(read_exactly(&mut peer, expected.len()).await, expected);

        // Already answered: written at once, by the caller.
        let (tx, rx) = oneshot::channel();
        tx.send(8).expect("receiver alive");
        assert!(out.reply_when_ready(vec![Bytes::new()], rx, encode).is_finished());
        let expected = reply_bytes(&8u32.to_be_bytes());
        assert_eq!(read_exactly(&mut peer, expected.len()).await, expected);

        // A dropped sender still gets its reply, from `encode(None)`.
        let (tx, rx) = oneshot::channel::<u32>();
        let handle = out.reply_when_ready(vec![Bytes::new()], rx, encode);
        drop(tx);
        assert!(handle.is_finished());
        let expected = reply_bytes(b"gone");
        assert_eq!(read_exactly(&mut peer, expected.len()).await, expected);
    }

    /// Whether `woken()` would resolve now.
    fn is_woken(out: &Outgoing) -> bool {
        let mut woken = std::pin::pin!(out.woken());
        woken.as_mut().poll(&mut Context::from_waker(Waker::noop())).is_ready()
    }

    #[tokio::test]
    async fn the_connection_task_is_woken_only_when_it_waits_for_the_reply() {
        let (out, mut peer) = pair().await;
        // The usual case: the task has nothing to serve until its peer sends more, so it
        // does not ask; the reply, written from another thread, wakes nobody.
        let (tx, rx) = oneshot::channel();
        out.reply_when_ready(vec![Bytes::new()], rx, encode);
        std::thread::spawn(move || tx.send(1).expect("receiver alive"))
            .join()
            .expect("thread");
        assert!(!is_woken(&out));
        read_exactly(&mut peer, reply_bytes(&1u32.to_be_bytes()).len()).await;
        // A task holding its next request asks, and is woken once the reply is out.
        let (tx, rx) = oneshot::channel();
        out.reply_when_ready(vec![Bytes::new()], rx, encode);
        assert!(!out.ready_for_request());
        assert!(!is_woken(&out));
        tx.send(2).expect("receiver alive");
        assert!(is_woken(&out));
        assert!(out.ready_for_request());
    }

    #[tokio::test]
    async fn an_aborted_reply_is_never_written_and_frees_the_connection() {
        let (out, mut peer) = pair().await;
        let (tx, rx) = oneshot::channel();
        let handle = out.reply_when_ready(vec![Bytes::new()], rx, encode);
        handle.abort();
        assert!(handle.is_finished());
        assert!(out.ready_for_request());
        assert!(tx.send(9).is_err(), "the receiver is gone");
        out.reply(&[Bytes::from_static(b"x")], b"after");
        let mut expected = Vec::new();
        zmtp::encode_message(&mut expected, &[b"x", b"after"]);
        assert_eq!(read_exactly(&mut peer, expected.len()).await, expected);
    }

    #[tokio::test]
    async fn what_the_socket_does_not_take_is_flushed_in_order() {
        let (out, mut peer) = pair().await;
        // Far more than a loopback socket buffers, so most of it is left pending.
        let big: Vec<u8> = (0..24u32 << 20).map(|i| i as u8).collect();
        out.reply(&[Bytes::new()], &big);
        assert!(out.has_pending());
        assert!(!out.ready_for_request(), "no new request while bytes are pending");
        out.write(b"tail");
        let flusher = {
            let out = out.clone();
            tokio::spawn(async move { out.flush().await })
        };
        let expected = [reply_bytes(&big), b"tail".to_vec()].concat();
        assert!(read_exactly(&mut peer, expected.len()).await == expected);
        flusher.await.expect("task").expect("flushed");
        assert!(!out.has_pending());
        assert!(out.ready_for_request());
    }

    #[tokio::test]
    async fn a_closed_side_drops_what_comes_later_and_releases_the_socket() {
        let (out, mut peer) = pair().await;
        let (tx, rx) = oneshot::channel();
        let handle = out.reply_when_ready(vec![Bytes::new()], rx, encode);
        out.close();
        tx.send(1).expect("receiver alive");
        assert!(handle.is_finished());
        let mut rest = Vec::new();
        tokio::time::timeout(Duration::from_secs(10), peer.read_to_end(&mut rest))
            .await
            .expect("closed within 10 s")
            .expect("read");
        assert!(rest.is_empty(), "{rest:?}");
    }
}
