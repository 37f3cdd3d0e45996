//! Progress and cancellation of the long calls ([`crate::lod_with`], and the facade's
//! `layers_with` and `envelope_with`).
//!
//! A call counts its steps up front (a level's sampling, its contouring, its envelope step;
//! the layers' filtering, extraction and ordering), and after each one hands a [`Progress`] to
//! the caller's callback. The callback answers [`Control::Continue`] or [`Control::Stop`]; a
//! stop ends the call with [`PyramidError::Cancelled`] before the next step starts, so the work stops
//! within one step (a level of a pyramid, at most). The callback may be called from any thread
//! (it is `Sync`); it should return quickly.

use crate::error::PyramidError;
use crate::lod::LodLevel;
use voxlod_envelope::EnvelopeLevel;

/// What the callback wants: go on, or stop at the next step boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Stop: the call returns [`PyramidError::Cancelled`].
    Stop,
}

/// Where a long call is.
#[derive(Clone, Copy, Debug)]
pub struct Progress<'a> {
    /// Steps finished.
    pub done: usize,
    /// Steps of the whole call.
    pub total: usize,
    /// What just finished.
    pub event: Event<'a>,
}

/// What just finished.
#[derive(Clone, Copy, Debug)]
pub enum Event<'a> {
    /// The work is planned and about to start (`done` is 0).
    Started,
    /// One step of level `level`: `what` is `"sampled"`, `"contoured"`, `"simplified"`,
    /// `"filtered"`, `"extracted"` or `"ordered"`; for a proxy `"proxy levels"` (the
    /// portfolio), `"atlases"` (every level's atlas, made side by side, about to start) and
    /// `"bake"`.
    Step {
        /// The level (0 for a call with one level).
        level: usize,
        /// The step.
        what: &'static str,
    },
    /// A level of [`crate::lod_with`], complete.
    LodLevel(&'a LodLevel),
    /// A level of `voxlod::envelope_with`, complete.
    EnvelopeLevel(&'a EnvelopeLevel),
}

/// The callback of the long calls.
pub type ProgressFn<'f> = dyn Fn(Progress<'_>) -> Control + Sync + 'f;

/// A callback that lets the work run to its end (what the calls without `_with` use).
pub fn run_to_end(_: Progress<'_>) -> Control {
    Control::Continue
}

/// Counts the steps of one call and asks the callback after each.
pub struct Tracker<'f> {
    callback: &'f ProgressFn<'f>,
    done: usize,
    total: usize,
}

impl<'f> Tracker<'f> {
    /// Reports the start of `total` steps.
    pub fn start(callback: &'f ProgressFn<'f>, total: usize) -> Result<Self, PyramidError> {
        let tracker = Tracker {
            callback,
            done: 0,
            total,
        };
        tracker.ask(Event::Started)?;
        Ok(tracker)
    }

    /// One step done.
    pub fn step(&mut self, level: usize, what: &'static str) -> Result<(), PyramidError> {
        self.done += 1;
        self.ask(Event::Step { level, what })
    }

    /// Reports `event` without counting a step (a level complete).
    pub fn ask(&self, event: Event<'_>) -> Result<(), PyramidError> {
        let progress = Progress {
            done: self.done.min(self.total),
            total: self.total,
            event,
        };
        match (self.callback)(progress) {
            Control::Continue => Ok(()),
            Control::Stop => Err(PyramidError::Cancelled),
        }
    }
}
