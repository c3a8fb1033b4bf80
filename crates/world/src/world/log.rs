//! The simulation log: `print` and `sim.addLog` from scripts and the API, kept in a
//! bounded ring so a chatty script cannot grow memory, and mirrored to `tracing`.

use std::collections::VecDeque;

/// How many log lines are kept.
pub const LOG_CAPACITY: usize = 2000;

/// One log line.
#[derive(Debug, Clone, PartialEq)]
pub struct LogLine {
    /// Monotonic sequence number, so readers can ask for lines after the last they saw.
    pub seq: u64,
    /// Simulation time when logged, s.
    pub sim_time: f64,
    /// CoppeliaSim verbosity (200 errors, 300 warnings, 450 script infos, 500 infos).
    pub verbosity: i64,
    /// Who logged it, e.g. a script's file name.
    pub source: String,
    /// The text.
    pub message: String,
}

/// The bounded log.
#[derive(Debug, Clone, Default)]
pub struct Log {
    lines: VecDeque<LogLine>,
    next_seq: u64,
    /// Titles of the auxiliary consoles scripts opened (`sim.auxiliaryConsoleOpen`), by
    /// handle - [`FIRST_CONSOLE_HANDLE`]; `None` once closed. Their text goes to the log
    /// (which the viewer shows) under the console's title.
    consoles: Vec<Option<String>>,
}

/// The first auxiliary console handle; later ones count up and are never reused.
pub const FIRST_CONSOLE_HANDLE: i64 = 3_000_000;

impl Log {
    /// Appends a line (dropping the oldest past [`LOG_CAPACITY`]) and mirrors it to tracing.
    pub fn push(&mut self, sim_time: f64, verbosity: i64, source: &str, message: &str) {
        match verbosity {
            ..=200 => tracing::error!(target: "script", "[{source}] {message}"),
            201..=300 => tracing::warn!(target: "script", "[{source}] {message}"),
            _ => tracing::info!(target: "script", "[{source}] {message}"),
        }
        if self.lines.len() == LOG_CAPACITY {
            self.lines.pop_front();
        }
        self.lines.push_back(LogLine {
            seq: self.next_seq,
            sim_time,
            verbosity,
            source: source.to_owned(),
            message: message.to_owned(),
        });
        self.next_seq += 1;
    }

    /// Lines with a sequence number of at least `from`, oldest first.
    pub fn since(&self, from: u64) -> impl Iterator<Item = &LogLine> {
        self.lines.iter().filter(move |l| l.seq >= from)
    }

    /// Opens an auxiliary console titled `title`; returns its handle.
    pub fn open_console(&mut self, title: &str) -> i64 {
        self.consoles.push(Some(title.to_owned()));
        FIRST_CONSOLE_HANDLE + self.consoles.len() as i64 - 1
    }

    /// The title of open console `h`.
    pub fn console(&self, h: i64) -> Option<&str> {
        let i = usize::try_from(h.checked_sub(FIRST_CONSOLE_HANDLE)?).ok()?;
        self.consoles.get(i)?.as_deref()
    }

    /// Closes console `h`; whether it was open.
    pub fn close_console(&mut self, h: i64) -> bool {
        let Some(i) = h
            .checked_sub(FIRST_CONSOLE_HANDLE)
            .and_then(|i| usize::try_from(i).ok())
        else {
            return false;
        };
        self.consoles.get_mut(i).and_then(Option::take).is_some()
    }

    /// Every kept line, oldest first.
    pub fn lines(&self) -> impl Iterator<Item = &LogLine> {
        self.lines.iter()
    }
}
