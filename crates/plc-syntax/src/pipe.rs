//! A [`RungSink`] run on a second thread: the reader reads the next rungs while the sink (the
//! resolver) resolves the ones before, so that loading a big program uses two cores.
//!
//! [`through_pipe`] hands `read` a sink of its own. At `start` the real sink moves to a scoped
//! thread with the variables (it declares them there while the reader reads the first rungs)
//! and receives the rungs in batches of [`BATCH`] over a bounded channel, in file order.
//! Anything else the reader says to the sink (a `retract`, a second `start`) first waits for
//! the thread to take every rung sent so far, so the sink sees exactly the calls, in exactly
//! the order, it would have seen on the reader's thread: the result is the same, only sooner.
//!
//! Invariants: at most [`DEPTH`] batches are in flight (the memory of rungs read ahead is
//! bounded); the sink is back on the caller's thread when `through_pipe` returns; a panic of
//! the sink's thread is resumed on the caller's.
//!
//! Deliberately not here: deciding when two threads pay off (the caller does: a small file is
//! read faster on one).

use super::{Rung, RungSink, Var};
use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::{Scope, ScopedJoinHandle};

/// Rungs per message: enough that the channel costs nothing per rung, few enough that the
/// resolver starts early and the rungs read ahead stay in cache.
pub const BATCH: usize = 256;
/// Batches in flight before the reader waits for the resolver.
pub const DEPTH: usize = 8;

/// Runs `read` with a sink that passes everything on to `sink`, which resolves the rungs on a
/// second thread while `read` goes on reading.
pub fn through_pipe<'a, S, R>(sink: &mut S, read: impl FnOnce(&mut dyn RungSink<'a>) -> R) -> R
where
    S: RungSink<'a> + Send,
{
    std::thread::scope(|scope| {
        let mut pipe = Pipe {
            scope,
            place: Place::Here(sink),
            batch: Vec::new(),
        };
        let result = read(&mut pipe);
        pipe.bring_back();
        result
    })
}

/// Where the sink is.
enum Place<'scope, 'a, 's, S> {
    /// On the caller's thread.
    Here(&'s mut S),
    /// On its own thread, fed by `tx`; it gives the sink back when the channel closes.
    Away {
        tx: SyncSender<Vec<Rung<'a>>>,
        thread: ScopedJoinHandle<'scope, &'s mut S>,
    },
    /// Only while moving between the two.
    Moving,
}

struct Pipe<'scope, 'env, 'a, 's, S> {
    scope: &'scope Scope<'scope, 'env>,
    place: Place<'scope, 'a, 's, S>,
    /// Rungs read and not sent yet.
    batch: Vec<Rung<'a>>,
}

impl<'scope, 'env, 'a, 's, S> Pipe<'scope, 'env, 'a, 's, S>
where
    S: RungSink<'a> + Send,
{
    /// The sink, on this thread: every rung sent has been given to it.
    fn bring_back(&mut self) -> &mut S {
        self.send();
        if let Place::Away { .. } = self.place {
            let Place::Away { tx, thread } = std::mem::replace(&mut self.place, Place::Moving)
            else {
                unreachable!("matched just above")
            };
            drop(tx);
            let sink = match thread.join() {
                Ok(sink) => sink,
                Err(panic) => std::panic::resume_unwind(panic),
            };
            self.place = Place::Here(sink);
        }
        match &mut self.place {
            Place::Here(sink) => sink,
            _ => unreachable!("the sink was brought back"),
        }
    }

    /// Sends the batch read so far to the sink's thread (if it is away).
    fn send(&mut self) {
        if self.batch.is_empty() {
            return;
        }
        let batch = std::mem::replace(&mut self.batch, Vec::with_capacity(BATCH));
        if let Place::Away { tx, .. } = &self.place {
            // The thread only stops receiving when it panicked: `bring_back` resumes that.
            let _ = tx.send(batch);
        }
    }
}

impl<'scope, 'env, 'a, 's, S> RungSink<'a> for Pipe<'scope, 'env, 'a, 's, S>
where
    S: RungSink<'a> + Send,
    'a: 'scope,
    's: 'scope,
{
    fn start(&mut self, vars: Vec<Var<'a>>, rungs: usize) {
        self.bring_back();
        let Place::Here(sink) = std::mem::replace(&mut self.place, Place::Moving) else {
            unreachable!("brought back above")
        };
        let (tx, rx) = sync_channel::<Vec<Rung<'a>>>(DEPTH);
        let thread = self.scope.spawn(move || {
            sink.start(vars, rungs);
            for batch in rx {
                for rung in batch {
                    sink.rung(rung);
                }
            }
            sink
        });
        self.place = Place::Away { tx, thread };
        self.batch = Vec::with_capacity(BATCH);
    }

    fn rung(&mut self, rung: Rung<'a>) {
        match &mut self.place {
            Place::Here(sink) => sink.rung(rung),
            _ => {
                self.batch.push(rung);
                if self.batch.len() >= BATCH {
                    self.send();
                }
            }
        }
    }

    fn retract(&mut self) {
        self.bring_back().retract();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Name, Origin};

    /// Records every call, as text.
    #[derive(Default)]
    struct Log {
        calls: Vec<String>,
    }

    impl<'a> RungSink<'a> for Log {
        fn start(&mut self, vars: Vec<Var<'a>>, rungs: usize) {
            self.calls.push(format!("start {} {rungs}", vars.len()));
        }
        fn rung(&mut self, rung: Rung<'a>) {
            self.calls.push(format!("rung {}", rung.id.as_str()));
        }
        fn retract(&mut self) {
            self.calls.push("retract".into());
        }
    }

    fn rung(id: &str) -> Rung<'_> {
        Rung {
            origin: Origin::at(0),
            id: Name {
                value: id.into(),
                origin: Origin::at(0),
            },
            label: None,
            comment: None,
            ld: Vec::new(),
            ld_origin: Origin::at(0),
            problem: None,
            problem_in_rung: false,
        }
    }

    /// The calls `script` makes, straight and through the pipe.
    #[test]
    fn the_sink_sees_the_same_calls_in_the_same_order() {
        fn script<'a>(ids: &'a [String], sink: &mut dyn RungSink<'a>) {
            sink.start(Vec::new(), 7);
            for id in &ids[..600] {
                sink.rung(rung(id));
            }
            sink.retract();
            sink.start(Vec::new(), 3);
            for id in &ids[600..] {
                sink.rung(rung(id));
            }
        }
        let ids: Vec<String> = (0..1000).map(|i| format!("R{i}")).collect();
        let mut straight = Log::default();
        script(&ids, &mut straight);
        let mut piped = Log::default();
        through_pipe(&mut piped, |sink| script(&ids, sink));
        assert_eq!(piped.calls, straight.calls);
        assert_eq!(piped.calls.len(), 1003);
        assert_eq!(piped.calls[601], "retract");
    }
}
