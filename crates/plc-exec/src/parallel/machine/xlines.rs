//! The exchange lines of a `par-exchange` run (`exchange`): per key of the plan's
//! [`Exchange`], lines of seven data words and a sequence number (the scan + 1), stored with
//! Release after the data and waited for with Acquire, so the data and its readiness travel in
//! one line and waiting for all the others' lines of a phase is the phase's barrier. Two sets of
//! lines alternate by scan parity (why that suffices: `exchange`). Packing: a run of BOOL bytes
//! (each 0 or 1) as bits, 64 to a word (on x86_64 by SSE2's byte mask, 16 bytes an
//! instruction); other bytes 8 to a word. A segment's last, partial word reads the whole word's
//! bytes from the state when they lie inside it and masks off those past the segment (no copy
//! of a variable length per segment); unpacking writes exactly the segment's bytes. Knows
//! nothing of plans beyond the keys.

use super::backoff::{wait_until, Pace};
use super::barrier::SpinBarrier;
use crate::parallel::planning::{Exchange, Key, LINE_WORDS};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// One exchange line: seven data words and the sequence number of the scan that wrote them.
#[repr(align(64))]
struct XLine([AtomicU64; 8]);

/// The exchange lines of a run: two sets (by scan parity) of a plan's [`Exchange::lines`].
pub(super) struct XBuffer {
    lines: Box<[XLine]>,
    per_set: usize,
}

const PACE: Pace = Pace {
    spins: 20_000,
    yield_for: Duration::from_micros(200),
};
const PARK: Duration = Duration::from_micros(20);

/// Bit 0 of each byte of a little-endian word packed into its 8 low bits (byte j → bit j):
/// with only bit 0 of each byte kept, each byte's bit lands at a distinct position of the top
/// byte, no two terms overlap, so nothing carries.
#[inline(always)]
fn pack8(v: u64) -> u64 {
    (v & 0x0101_0101_0101_0101).wrapping_mul(0x0102_0408_1020_4080) >> 56
}

/// Bit 0 of each of 64 bytes as a word (byte i → bit i): a run of BOOL bytes (each 0 or 1) as
/// bits (on x86_64 16 bytes at a time by SSE2: `raw::pack_bools`).
#[inline(always)]
fn pack64(c: &[u8; 64]) -> u64 {
    #[cfg(target_arch = "x86_64")]
    {
        let mut w = 0;
        for (k, q) in c.as_chunks::<16>().0.iter().enumerate() {
            w |= u64::from(crate::raw::pack_bools(q)) << (16 * k);
        }
        w
    }
    #[cfg(not(target_arch = "x86_64"))]
    pack64_portable(c)
}

/// [`pack64`] without SIMD: one multiplication per 8 bytes.
#[inline(always)]
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
fn pack64_portable(c: &[u8; 64]) -> u64 {
    let mut w = 0;
    for (j, b) in c.as_chunks::<8>().0.iter().enumerate() {
        w |= pack8(u64::from_le_bytes(*b)) << (8 * j);
    }
    w
}

/// The mask of the low `bits` bits (`bits` < 64).
#[inline(always)]
fn low_bits(bits: usize) -> u64 {
    (1u64 << bits) - 1
}

/// Bit i of the index → byte i (0 or 1) of the word.
const SPREAD: [u64; 256] = {
    let mut t = [0u64; 256];
    let mut i = 0;
    while i < 256 {
        let mut b = 0;
        while b < 8 {
            if i & (1 << b) != 0 {
                t[i] |= 1 << (8 * b);
            }
            b += 1;
        }
        i += 1;
    }
    t
};

/// A word of bits as 64 BOOL bytes.
#[inline(always)]
fn unpack64(w: u64, c: &mut [u8; 64]) {
    for (j, b) in c.as_chunks_mut::<8>().0.iter_mut().enumerate() {
        *b = SPREAD[((w >> (8 * j)) & 0xff) as usize].to_le_bytes();
    }
}

impl XBuffer {
    pub(super) fn new(x: &Exchange) -> XBuffer {
        let per_set = x.lines as usize;
        let lines = (0..2 * per_set)
            .map(|_| XLine(Default::default()))
            .collect();
        XBuffer { lines, per_set }
    }

    #[inline(always)]
    fn line(&self, seq: u64, key: &Key, l: usize) -> &XLine {
        &self.lines[(seq & 1) as usize * self.per_set + key.first_line as usize + l]
    }

    #[inline(always)]
    fn word(&self, seq: u64, key: &Key, i: u32) -> &AtomicU64 {
        let i = i as usize;
        &self.line(seq, key, i / LINE_WORDS).0[i % LINE_WORDS]
    }

    /// Asks the CPU to fetch `key`'s lines of scan `seq − 1` for reading (a hint: a reader
    /// that expects them written soon overlaps their transfer with its work).
    pub(super) fn prefetch_read(&self, key: &Key, seq: u64) {
        for l in 0..key.lines as usize {
            plc_hint::prefetch_read(std::ptr::from_ref(self.line(seq, key, l)).cast());
        }
    }

    /// Asks the CPU to take `key`'s lines of scan `seq − 1` for writing (a hint: the writer
    /// takes them from the reader's cache now, not when it packs).
    pub(super) fn prefetch_write(&self, key: &Key, seq: u64) {
        for l in 0..key.lines as usize {
            plc_hint::prefetch_write(std::ptr::from_ref(self.line(seq, key, l)).cast());
        }
    }

    /// Packs `key`'s bytes of `state` into its lines and marks them as scan `seq − 1`'s.
    pub(super) fn pack(&self, key: &Key, state: &[u8], seq: u64) {
        let put = |i: u32, v: u64| self.word(seq, key, i).store(v, Ordering::Relaxed);
        for s in &key.segments {
            let at = s.at as usize;
            let bytes = &state[at..at + s.len as usize];
            if s.bools {
                let (chunks, tail) = bytes.as_chunks::<64>();
                for (i, c) in chunks.iter().enumerate() {
                    put(s.word + i as u32, pack64(c));
                }
                if !tail.is_empty() {
                    let from = at + 64 * chunks.len();
                    let w = match state.get(from..from + 64) {
                        Some(c) => pack64(c.as_array().expect("64 bytes")) & low_bits(tail.len()),
                        None => {
                            let mut c = [0u8; 64];
                            c[..tail.len()].copy_from_slice(tail);
                            pack64(&c)
                        }
                    };
                    put(s.word + chunks.len() as u32, w);
                }
            } else {
                let (words, tail) = bytes.as_chunks::<8>();
                for (i, c) in words.iter().enumerate() {
                    put(s.word + i as u32, u64::from_le_bytes(*c));
                }
                if !tail.is_empty() {
                    let from = at + 8 * words.len();
                    let w = match state.get(from..from + 8) {
                        Some(c) => {
                            let c = c.as_array().expect("8 bytes");
                            u64::from_le_bytes(*c) & low_bits(8 * tail.len())
                        }
                        None => {
                            let mut b = [0u8; 8];
                            b[..tail.len()].copy_from_slice(tail);
                            u64::from_le_bytes(b)
                        }
                    };
                    put(s.word + words.len() as u32, w);
                }
            }
        }
        for l in 0..key.lines as usize {
            self.line(seq, key, l).0[LINE_WORDS].store(seq, Ordering::Release);
        }
    }

    /// Waits until every line of `key` is scan `seq − 1`'s; false if a worker panicked.
    pub(super) fn wait(&self, key: &Key, seq: u64, barrier: &SpinBarrier) -> bool {
        for l in 0..key.lines as usize {
            let flag = &self.line(seq, key, l).0[LINE_WORDS];
            if flag.load(Ordering::Acquire) == seq {
                continue;
            }
            let ready = || (flag.load(Ordering::Acquire) == seq).then_some(());
            let park = || {
                if barrier.is_poisoned() {
                    return false;
                }
                std::thread::park_timeout(PARK);
                true
            };
            if wait_until(barrier.pace(PACE), ready, park).is_none() {
                return false;
            }
        }
        true
    }

    /// Unpacks `key`'s lines (waited for) into `state`.
    pub(super) fn unpack(&self, key: &Key, state: &mut [u8], seq: u64) {
        let get = |i: u32| self.word(seq, key, i).load(Ordering::Relaxed);
        for s in &key.segments {
            let bytes = &mut state[s.at as usize..(s.at + s.len) as usize];
            if s.bools {
                let (chunks, tail) = bytes.as_chunks_mut::<64>();
                let n = chunks.len() as u32;
                for (i, c) in chunks.iter_mut().enumerate() {
                    unpack64(get(s.word + i as u32), c);
                }
                if !tail.is_empty() {
                    // The partial word in place: its whole groups of 8, then the rest.
                    let w = get(s.word + n);
                    let (groups, rest) = tail.as_chunks_mut::<8>();
                    for (j, g) in groups.iter_mut().enumerate() {
                        *g = SPREAD[((w >> (8 * j)) & 0xff) as usize].to_le_bytes();
                    }
                    if !rest.is_empty() {
                        let j = groups.len();
                        let g = SPREAD[((w >> (8 * j)) & 0xff) as usize].to_le_bytes();
                        let k = rest.len();
                        rest.copy_from_slice(&g[..k]);
                    }
                }
            } else {
                let (words, rest) = bytes.as_chunks_mut::<8>();
                for (i, c) in words.iter_mut().enumerate() {
                    *c = get(s.word + i as u32).to_le_bytes();
                }
                if !rest.is_empty() {
                    let k = rest.len();
                    let w = get(s.word + words.len() as u32).to_le_bytes();
                    rest.copy_from_slice(&w[..k]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::planning::Segment;

    /// A pseudo-random byte per call.
    fn bytes(seed: u64) -> impl FnMut() -> u8 {
        let mut rng = fastrand::Rng::with_seed(seed);
        move || rng.u8(..)
    }

    /// `pack64` (and its portable form, which other architectures run) keeps bit 0 of each
    /// byte, whatever the other bits (a segment's last word reads bytes past it, which are not
    /// BOOLs).
    #[test]
    fn a_word_holds_bit_zero_of_each_byte() {
        let mut next = bytes(7);
        for _ in 0..1000 {
            let c: [u8; 64] = std::array::from_fn(|_| next());
            let want = (0..64).fold(0u64, |w, i| w | u64::from(c[i] & 1) << i);
            assert_eq!(pack64(&c), want, "{c:?}");
            assert_eq!(pack64_portable(&c), want, "{c:?}");
        }
    }

    /// One key of segments of every length from 1 to 130 bytes, BOOL and other, each followed
    /// by bytes that are not its own (and the last at the end of the state, where its last word
    /// cannot be read whole): unpacking into a state of other bytes writes exactly the
    /// segments' bytes.
    #[test]
    fn segments_round_trip_and_unpacking_writes_only_their_bytes() {
        for bools in [true, false] {
            let mut next = bytes(if bools { 11 } else { 12 });
            let mut segments = Vec::new();
            let (mut at, mut word) = (0u32, 0u32);
            for len in 1..=130u32 {
                let s = Segment {
                    at,
                    len,
                    bools,
                    word,
                };
                word += s.words();
                segments.push(s);
                at += len + 3;
            }
            let end = segments.last().map_or(0, |s| s.at + s.len) as usize;
            let mut state: Vec<u8> = (0..end).map(|_| next()).collect();
            for s in &segments {
                for b in &mut state[s.at as usize..(s.at + s.len) as usize] {
                    if bools {
                        *b &= 1;
                    }
                }
            }
            let lines = word.div_ceil(LINE_WORDS as u32);
            let key = Key {
                segments: segments.clone(),
                first_line: 0,
                lines,
            };
            let x = Exchange {
                threads: 1,
                keys: vec![key.clone()],
                splits: Vec::new(),
                inputs: Key::default(),
                lines,
            };
            let buf = XBuffer::new(&x);
            buf.pack(&key, &state, 5);
            let mut other: Vec<u8> = (0..end).map(|_| next()).collect();
            let mut want = other.clone();
            for s in &segments {
                let r = s.at as usize..(s.at + s.len) as usize;
                want[r.clone()].copy_from_slice(&state[r]);
            }
            buf.unpack(&key, &mut other, 5);
            assert_eq!(other, want, "bools {bools}");
        }
    }

    #[test]
    fn bools_round_trip_through_a_word() {
        let mut c = [0u8; 64];
        for (i, b) in c.iter_mut().enumerate() {
            *b = ((i * 7 + i / 5) % 3 == 0) as u8;
        }
        let w = pack64(&c);
        for (i, b) in c.iter().enumerate() {
            assert_eq!((w >> i) & 1, *b as u64, "bit {i}");
        }
        let mut back = [9u8; 64];
        unpack64(w, &mut back);
        assert_eq!(back, c);
        for v in 0..=255u64 {
            assert_eq!(pack8(SPREAD[v as usize]), v);
        }
    }
}
