//! A writer that hands full buffers to a thread of its own, so that rendering a big output and
//! the kernel's copy of it into the file overlap on two cores instead of taking turns.
//!
//! Writing a 1 GB JSON report spends about a tenth of its time in `write(2)` (the copy into the
//! page cache); on one thread that time adds to the rendering, with [`write_in_background`] the
//! renderer goes on filling the next buffer meanwhile. Output stays byte-identical and in order:
//! buffers are sent through a bounded channel and written in the order they were filled.
//!
//! Invariants: at most [`IN_FLIGHT`] full buffers wait, so memory stays bounded by
//! `(IN_FLIGHT + 2) × BUFFER` whatever the output's size; the first I/O error of the writing
//! thread is the result (a renderer that writes on after it gets `BrokenPipe` and stops). It
//! deliberately does not make writing atomic: the caller writes to a temporary file and renames.

use std::io::{self, Write};
use std::sync::mpsc::{sync_channel, SyncSender};

/// Size of one buffer.
const BUFFER: usize = 1 << 20;
/// Full buffers that may wait for the writing thread.
const IN_FLIGHT: usize = 2;

/// The renderer's side: fills a buffer and sends it when full.
struct Sender {
    buffer: Vec<u8>,
    to_writer: SyncSender<Vec<u8>>,
}

impl Sender {
    fn send(&mut self) -> io::Result<()> {
        if self.buffer.is_empty() {
            return Ok(());
        }
        let full = std::mem::replace(&mut self.buffer, Vec::with_capacity(BUFFER));
        // The writing thread hung up: it met an error, which `write_in_background` returns.
        self.to_writer
            .send(full)
            .map_err(|_| io::Error::from(io::ErrorKind::BrokenPipe))
    }
}

impl Write for Sender {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        self.write_all(data).map(|()| data.len())
    }

    fn write_all(&mut self, mut data: &[u8]) -> io::Result<()> {
        while !data.is_empty() {
            let room = BUFFER - self.buffer.len();
            let (now, later) = data.split_at(room.min(data.len()));
            self.buffer.extend_from_slice(now);
            if self.buffer.len() == BUFFER {
                self.send()?;
            }
            data = later;
        }
        Ok(())
    }

    /// Hands what is buffered to the writing thread (which flushes `sink` at the end).
    fn flush(&mut self) -> io::Result<()> {
        self.send()
    }
}

/// Runs `render` with a writer whose buffers a second thread writes to `sink`; returns the
/// first error of either side, the writing thread's first (it explains a renderer's
/// `BrokenPipe`). `sink` is flushed at the end.
pub(super) fn write_in_background<W: Write + Send>(
    sink: &mut W,
    render: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let (to_writer, buffers) = sync_channel::<Vec<u8>>(IN_FLIGHT);
    std::thread::scope(|scope| {
        let writer = scope.spawn(move || -> io::Result<()> {
            for buffer in buffers {
                sink.write_all(&buffer)?;
            }
            sink.flush()
        });
        let mut sender = Sender {
            buffer: Vec::with_capacity(BUFFER),
            to_writer,
        };
        let rendered = render(&mut sender).and_then(|()| sender.flush());
        drop(sender);
        let written = writer
            .join()
            .unwrap_or_else(|_| Err(io::Error::other("the writing thread panicked")));
        written.and(rendered)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_arrives_whole_and_in_order_across_many_buffers() {
        let mut sink = Vec::new();
        let expected: Vec<u8> = (0..3 * BUFFER + 12_345).map(|i| (i % 251) as u8).collect();
        write_in_background(&mut sink, |w| {
            for chunk in expected.chunks(7_777) {
                w.write_all(chunk)?;
            }
            Ok(())
        })
        .unwrap();
        assert_eq!(sink, expected);
    }

    /// Accepts `room` bytes, then fails as a full disk does.
    struct Full {
        room: usize,
    }

    impl Write for Full {
        fn write(&mut self, data: &[u8]) -> io::Result<usize> {
            if data.len() > self.room {
                return Err(io::Error::new(io::ErrorKind::StorageFull, "disk full"));
            }
            self.room -= data.len();
            Ok(data.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn the_writing_threads_error_is_the_result_and_stops_the_renderer() {
        let mut sink = Full { room: BUFFER };
        let mut written = 0usize;
        let e = write_in_background(&mut sink, |w| {
            for _ in 0..100 {
                w.write_all(&[b'x'; BUFFER / 2])?;
                written += BUFFER / 2;
            }
            Ok(())
        })
        .unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::StorageFull);
        // The renderer stopped soon after the failure instead of rendering all 50 MB.
        assert!(written <= (IN_FLIGHT + 4) * BUFFER, "{written}");
    }

    #[test]
    fn a_renderers_error_is_returned_after_what_it_wrote_is_written() {
        let mut sink = Vec::new();
        let e = write_in_background(&mut sink, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("render failed"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), "render failed");
    }
}
