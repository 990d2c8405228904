//! A window of recent samples, addressed by absolute sample index, shared read-only by all
//! channels while they correlate and refilled from the source between rounds — or beside
//! other work: [`SampleWindow::fill_during`] reads the next block into spare room behind the
//! samples held while the channels work on those, [`SampleWindow::read_during`] while the
//! calling thread does work that needs no sample (the navigation after a round).
//!
//! Memory is bounded: samples older than the slowest channel's next integration are dropped.
//! Nothing is allocated or zeroed per block in the steady state: the buffer keeps its size and
//! the live samples are moved to its front only when the dropped prefix is as long as they
//! are.
//!
//! Samples are held as integers when the source can hand them over that way
//! ([`SampleSource::integer_format`]): complex ci8/ci16 at IF 0 as stored, every other integer
//! format (cu8, ri8, ri16, or ci8/ci16 mixed from an IF) converted to ci16 when read
//! ([`gpsrx_samples::held_gain`]) -- the int16 correlators read those in place, with a half or
//! a quarter of the memory traffic of complex f32 -- else as complex f32. The searches, which
//! need f32, convert the span they read.

use crate::pipeline::profile::timed;
use gpsrx_dsp::correlator::SampleSlice;
use gpsrx_samples::{IntegerFormat, IntegerSamplesMut, SampleError, SampleSource};
use num_complex::Complex32;
use std::borrow::Cow;
use std::time::Duration;

/// Samples processed per block, as a fraction of a second (40 ms). Each block wakes the worker
/// threads once; with the correlators at 6 instructions per sample, the wake-ups of 10 ms
/// blocks were 15 % of a run (60 s, 4 MHz ci8, 12 channels, AVX2: 1.28 s wall with 10 ms
/// blocks, 1.15 s with 20 ms, 1.09 s with 40 ms; memory unchanged).
const BLOCK_S: f64 = 0.04;

/// Samples per processing block (40 ms of signal) at `fs_hz`: the unit in which the window is
/// filled and the channels work.
pub fn block_samples(fs_hz: f64) -> usize {
    ((fs_hz * BLOCK_S).ceil() as usize).max(1)
}

/// One complex sample as the window may hold it.
trait Held: Copy + Default + Send + Sync {
    /// The samples as the correlators read them.
    fn slice(s: &[Self]) -> SampleSlice<'_>;
}

impl Held for Complex32 {
    fn slice(s: &[Self]) -> SampleSlice<'_> {
        SampleSlice::Cf32(s)
    }
}

impl Held for [i8; 2] {
    fn slice(s: &[Self]) -> SampleSlice<'_> {
        SampleSlice::Ci8(s)
    }
}

impl Held for [i16; 2] {
    fn slice(s: &[Self]) -> SampleSlice<'_> {
        SampleSlice::Ci16(s)
    }
}

/// `buf[head..tail]` are the live samples; `buf[tail..]` is room for the next reads
/// (initialised once, when the buffer grows).
#[derive(Debug, Default)]
struct Buffer<T> {
    buf: Vec<T>,
    head: usize,
    tail: usize,
}

impl<T: Held> Buffer<T> {
    fn live(&self) -> &[T] {
        &self.buf[self.head..self.tail]
    }

    fn len(&self) -> usize {
        self.tail - self.head
    }

    /// Makes room for `n` samples behind the live ones.
    fn reserve(&mut self, n: usize) {
        if self.buf.len() < self.tail + n {
            self.buf.resize(self.tail + n, T::default());
        }
    }

    /// The live samples and the room for `n` more.
    fn split(&mut self, n: usize) -> (&[T], &mut [T]) {
        self.reserve(n);
        let (held, room) = self.buf.split_at_mut(self.tail);
        (&held[self.head..], &mut room[..n])
    }

    /// Drops the first `n` live samples. Compacts when the dropped prefix is as long as the
    /// live samples and at least `compact_bytes` ([`COMPACT_BYTES`]): at most one copy per sample dropped (a
    /// quarter of one at 4 MHz ci8, where the live half second is 4 MB), and the buffer stays
    /// within twice the live span plus one block plus [`COMPACT_BYTES`].
    fn drop_front(&mut self, n: usize, compact_bytes: usize) {
        self.head += n.min(self.len());
        let least = compact_bytes / std::mem::size_of::<T>();
        if self.head >= (self.tail - self.head).max(least) {
            self.buf.copy_within(self.head..self.tail, 0);
            self.tail -= self.head;
            self.head = 0;
        }
    }

    /// Drops every live sample (a gap: the next ones do not follow them).
    fn clear(&mut self) {
        self.head = self.tail;
    }
}

/// Samples dropped, in bytes, before the live ones are moved to the front of the buffer (at
/// least; and at least as many as are live). 16 MiB kept up to 16 MB more resident than the
/// live span needs (a third of the peak memory of a 4 MHz ci8 run); with 2 MiB the live half
/// second of 4 MHz ci8 (5 MB) is moved once per half second dropped, about 50 ms of copying
/// in a 60 s run.
const COMPACT_BYTES: usize = 2 << 20;

/// The samples, in the format they are held in.
#[derive(Debug)]
enum Store {
    Cf32(Buffer<Complex32>),
    Ci8(Buffer<[i8; 2]>),
    Ci16(Buffer<[i16; 2]>),
}

impl Default for Store {
    fn default() -> Self {
        Store::Cf32(Buffer::default())
    }
}

/// Runs `$body` with `$b` bound to the store's buffer, whatever its sample type.
macro_rules! each {
    ($store:expr, $b:ident => $body:expr) => {
        match $store {
            Store::Cf32($b) => $body,
            Store::Ci8($b) => $body,
            Store::Ci16($b) => $body,
        }
    };
}

/// Recent samples `[start, start + len)` of a stream.
#[derive(Debug)]
pub struct SampleWindow {
    start: u64,
    store: Store,
    end_of_stream: bool,
    /// Bytes dropped before a compaction ([`COMPACT_BYTES`]; smaller in tests).
    compact_bytes: usize,
    /// Wall time spent reading the source, s.
    read_s: f64,
    /// The integers held are the source's values times this ([`SampleSource::integer_gain`]).
    gain: f32,
}

impl Default for SampleWindow {
    fn default() -> Self {
        Self {
            start: 0,
            store: Store::default(),
            end_of_stream: false,
            compact_bytes: COMPACT_BYTES,
            read_s: 0.0,
            gain: 1.0,
        }
    }
}

/// A read-only view of the samples a [`SampleWindow`] holds.
#[derive(Debug, Clone, Copy)]
pub struct SampleView<'a> {
    start: u64,
    data: SampleSlice<'a>,
}

/// `s[a..b]` of a sample slice of any format.
fn sub(s: SampleSlice<'_>, a: usize, b: usize) -> SampleSlice<'_> {
    match s {
        SampleSlice::Cf32(x) => SampleSlice::Cf32(&x[a..b]),
        SampleSlice::Ci8(x) => SampleSlice::Ci8(&x[a..b]),
        SampleSlice::Ci16(x) => SampleSlice::Ci16(&x[a..b]),
    }
}

impl<'a> SampleView<'a> {
    /// Absolute index of the first sample held.
    pub fn start(&self) -> u64 {
        self.start
    }

    /// Absolute index one past the last sample held.
    pub fn end(&self) -> u64 {
        self.start + self.data.len() as u64
    }

    /// The samples before `limit` only (none when `limit` is at or before the start).
    pub fn until(self, limit: u64) -> SampleView<'a> {
        let n = limit.saturating_sub(self.start).min(self.data.len() as u64) as usize;
        SampleView {
            start: self.start,
            data: sub(self.data, 0, n),
        }
    }

    /// Samples `[from, from + len)` if all are held, as held.
    pub fn get(&self, from: u64, len: usize) -> Option<SampleSlice<'a>> {
        if from < self.start || from + len as u64 > self.end() {
            return None;
        }
        let a = (from - self.start) as usize;
        Some(sub(self.data, a, a + len))
    }

    /// Samples `[from, from + len)` if all are held, as complex f32 (borrowed when held so,
    /// else converted: integer values are exact in f32).
    pub fn get_cf32(&self, from: u64, len: usize) -> Option<Cow<'a, [Complex32]>> {
        let to_c = |re: f32, im: f32| Complex32::new(re, im);
        Some(match self.get(from, len)? {
            SampleSlice::Cf32(x) => Cow::Borrowed(x),
            SampleSlice::Ci8(x) => Cow::Owned(
                x.iter()
                    .map(|&[i, q]| to_c(f32::from(i), f32::from(q)))
                    .collect(),
            ),
            SampleSlice::Ci16(x) => Cow::Owned(
                x.iter()
                    .map(|&[i, q]| to_c(f32::from(i), f32::from(q)))
                    .collect(),
            ),
        })
    }
}

impl SampleWindow {
    /// An empty window at sample 0, holding complex f32.
    pub fn new() -> Self {
        Self::default()
    }

    /// Holds the samples of `src` as the integers it hands over (as stored, or converted:
    /// [`SampleSource::integer_format`]), if it can and nothing is held yet (else nothing
    /// changes). Returns the format now held, if integer.
    pub fn hold_as_stored(&mut self, src: &dyn SampleSource) -> Option<IntegerFormat> {
        if each!(&self.store, b => b.len()) == 0 {
            self.store = match src.integer_format() {
                Some(IntegerFormat::Ci8) => Store::Ci8(Buffer::default()),
                Some(IntegerFormat::Ci16) => Store::Ci16(Buffer::default()),
                None => Store::Cf32(Buffer::default()),
            };
            self.gain = match self.store {
                Store::Cf32(_) => 1.0,
                _ => src.integer_gain(),
            };
        }
        match self.store {
            Store::Cf32(_) => None,
            Store::Ci8(_) => Some(IntegerFormat::Ci8),
            Store::Ci16(_) => Some(IntegerFormat::Ci16),
        }
    }

    /// The samples held.
    pub fn view(&self) -> SampleView<'_> {
        SampleView {
            start: self.start,
            data: each!(&self.store, b => Held::slice(b.live())),
        }
    }

    /// Absolute index of the first sample held.
    pub fn start(&self) -> u64 {
        self.start
    }

    /// Absolute index one past the last sample held.
    pub fn end(&self) -> u64 {
        self.start + each!(&self.store, b => b.len()) as u64
    }

    /// Wall time spent reading the source so far, s (each read timed on the thread that
    /// made it, beside the work of [`SampleWindow::fill_during`] or
    /// [`SampleWindow::read_during`]).
    pub fn read_s(&self) -> f64 {
        self.read_s
    }

    /// Whether the source is exhausted.
    #[cfg(test)]
    pub fn end_of_stream(&self) -> bool {
        self.end_of_stream
    }

    /// Samples `[from, from + len)` if all are held, as complex f32.
    pub fn get_cf32(&self, from: u64, len: usize) -> Option<Cow<'_, [Complex32]>> {
        self.view().get_cf32(from, len)
    }

    /// Drops samples before `index`.
    pub fn discard_before(&mut self, index: u64) {
        let index = index.min(self.end());
        if index <= self.start {
            return;
        }
        let n = (index - self.start) as usize;
        let compact_bytes = self.compact_bytes;
        each!(&mut self.store, b => b.drop_front(n, compact_bytes));
        self.start = index;
    }

    /// The factor from the source's values to the integers held (1 for f32 and for integers
    /// held as stored; [`gpsrx_samples::held_gain`]).
    pub fn gain(&self) -> f32 {
        self.gain
    }

    /// Appends samples that follow the ones held (a stream pushed block by block). A window
    /// holding integers (after a run from a source) goes over to f32 first (the source's
    /// values: the integers divided by the gain).
    pub fn push(&mut self, samples: &[Complex32]) {
        if !matches!(self.store, Store::Cf32(_)) {
            let gain = std::mem::replace(&mut self.gain, 1.0);
            let held = self.get_cf32(self.start, (self.end() - self.start) as usize);
            let held: Vec<Complex32> = held
                .map(Cow::into_owned)
                .unwrap_or_default()
                .into_iter()
                .map(|c| c / gain)
                .collect();
            let mut b = Buffer::default();
            b.split(held.len()).1.copy_from_slice(&held);
            b.tail = held.len();
            self.store = Store::Cf32(b);
        }
        if let Store::Cf32(b) = &mut self.store {
            b.split(samples.len()).1.copy_from_slice(samples);
            b.tail += samples.len();
        }
    }

    /// Reads up to `n` more samples from `src`; returns how many arrived (0 at the end).
    /// A source whose first sample index is not contiguous with the window (a gap) restarts
    /// the window at the new index.
    pub fn fill(&mut self, src: &mut dyn SampleSource, n: usize) -> Result<usize, SampleError> {
        Ok(self.fill_during(src, n, |_| ())?.0)
    }

    /// [`SampleWindow::fill`] while `work` runs on the samples held before it (concurrently,
    /// rayon `join`); returns the samples read and `work`'s result. `work` runs even when the
    /// read fails or the source has ended.
    pub fn fill_during<R: Send>(
        &mut self,
        src: &mut dyn SampleSource,
        n: usize,
        work: impl FnOnce(SampleView<'_>) -> R + Send,
    ) -> Result<(usize, R), SampleError> {
        if self.end_of_stream {
            return Ok((0, work(self.view())));
        }
        let start = self.start;
        let (read, r) = match &mut self.store {
            Store::Cf32(b) => {
                let (held, room) = b.split(n);
                let view = SampleView {
                    start,
                    data: Held::slice(held),
                };
                rayon::join(|| timed(|| src.read(room)), || work(view))
            }
            Store::Ci8(b) => {
                let (held, room) = b.split(n);
                let view = SampleView {
                    start,
                    data: Held::slice(held),
                };
                rayon::join(
                    || timed(|| src.read_integer(IntegerSamplesMut::Ci8(room))),
                    || work(view),
                )
            }
            Store::Ci16(b) => {
                let (held, room) = b.split(n);
                let view = SampleView {
                    start,
                    data: Held::slice(held),
                };
                rayon::join(
                    || timed(|| src.read_integer(IntegerSamplesMut::Ci16(room))),
                    || work(view),
                )
            }
        };
        Ok((self.take_read(read)?, r))
    }

    /// Reads up to `n` more samples from `src` on the rayon pool while `f` runs on the
    /// calling thread (which need not be one of the pool's; `f` need not be `Send`): for
    /// work that needs no sample, such as the navigation after a round. Returns the samples
    /// read (0 at the end of the source) and `f`'s result; `f` runs even when the read fails
    /// or the source has ended. Gaps as in [`SampleWindow::fill`].
    pub fn read_during<R>(
        &mut self,
        src: &mut dyn SampleSource,
        n: usize,
        f: impl FnOnce() -> R,
    ) -> Result<(usize, R), SampleError> {
        if self.end_of_stream {
            return Ok((0, f()));
        }
        let (read, r) = match &mut self.store {
            Store::Cf32(b) => {
                let room = b.split(n).1;
                beside(|| timed(|| src.read(room)), f)
            }
            Store::Ci8(b) => {
                let room = b.split(n).1;
                beside(
                    || timed(|| src.read_integer(IntegerSamplesMut::Ci8(room))),
                    f,
                )
            }
            Store::Ci16(b) => {
                let room = b.split(n).1;
                beside(
                    || timed(|| src.read_integer(IntegerSamplesMut::Ci16(room))),
                    f,
                )
            }
        };
        Ok((self.take_read(read)?, r))
    }

    /// Takes in the samples a read put behind the live ones (its result and how long it
    /// took); returns how many arrived (0: the source has ended).
    fn take_read(
        &mut self,
        (read, reading): (Result<(u64, usize), SampleError>, Duration),
    ) -> Result<usize, SampleError> {
        self.read_s += reading.as_secs_f64();
        let (first, got) = read?;
        if got == 0 {
            self.end_of_stream = true;
            return Ok(0);
        }
        let empty = each!(&self.store, b => b.len()) == 0;
        if empty {
            // First read, or the window was empty: adopt the source's index.
            self.start = first;
        } else if first != self.end() {
            // A gap in the stream: keep only the new samples.
            each!(&mut self.store, b => b.clear());
            self.start = first;
        }
        each!(&mut self.store, b => b.tail += got);
        Ok(got)
    }
}

/// Runs `pool` on the rayon pool while `here` runs on the calling thread (which need not be
/// `Send`); returns both results when both are done.
pub(crate) fn beside<T: Send, R>(
    pool: impl FnOnce() -> T + Send,
    here: impl FnOnce() -> R,
) -> (T, R) {
    let mut out = None;
    let r = rayon::in_place_scope(|scope| {
        scope.spawn(|_| out = Some(pool()));
        here()
    });
    // The scope returns once the spawned job has run (a panic in it is resumed here).
    let pooled = out.expect("the scope waits for its spawned job");
    (pooled, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sample `i` of `v` (real part), if held.
    fn re(v: &SampleView<'_>, i: u64) -> Option<f32> {
        v.get_cf32(i, 1).map(|s| s[0].re)
    }

    #[test]
    fn get_and_discard_by_absolute_index() {
        let mut w = SampleWindow::new();
        w.start = 100;
        w.push(
            &(0..10)
                .map(|i| Complex32::new(i as f32, 0.0))
                .collect::<Vec<_>>(),
        );
        assert_eq!(w.end(), 110);
        assert_eq!(re(&w.view(), 103), Some(3.0));
        assert!(w.get_cf32(99, 2).is_none());
        assert!(w.get_cf32(109, 2).is_none());
        w.discard_before(106);
        assert_eq!(w.start(), 106);
        assert_eq!(w.get_cf32(106, 4).map(|s| s[3].re), Some(9.0));
        assert!(w.get_cf32(105, 1).is_none());
    }

    /// A source counting up from `first`: sample k is k + 0j.
    struct Counter {
        next: u64,
        end: u64,
    }

    impl SampleSource for Counter {
        fn fs_hz(&self) -> f64 {
            1e3
        }
        fn format(&self) -> &gpsrx_samples::SampleFormat {
            &gpsrx_samples::SampleFormat::Cf32Le
        }
        fn total_samples(&self) -> Option<u64> {
            None
        }
        fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
            let first = self.next;
            let n = (out.len() as u64).min(self.end - self.next) as usize;
            for (k, o) in out[..n].iter_mut().enumerate() {
                *o = Complex32::new((first + k as u64) as f32, 0.0);
            }
            self.next += n as u64;
            Ok((first, n))
        }
        fn warnings(&self) -> Vec<String> {
            Vec::new()
        }
    }

    #[test]
    fn fill_during_shows_the_held_samples_and_appends_the_read_ones() {
        let mut src = Counter {
            next: 50,
            end: 2000,
        };
        let mut w = SampleWindow::new();
        w.compact_bytes = 0;
        let mut seen_ends = Vec::new();
        for round in 0..40u64 {
            let (got, seen) = w
                .fill_during(&mut src, 30, |v| {
                    // The work sees exactly what was held before this read, values = indices.
                    let ok = (v.start()..v.end()).all(|i| re(&v, i) == Some(i as f32));
                    (v.end(), ok)
                })
                .unwrap_or_else(|e| panic!("{e}"));
            assert!(seen.1, "round {round}: view holds wrong samples");
            seen_ends.push(seen.0);
            assert_eq!(got, 30);
            assert_eq!(w.end(), 50 + 30 * (round + 1));
            // Keep the last 45 samples, as a slow channel would.
            w.discard_before(w.end().saturating_sub(45));
            let size = each!(&w.store, b => b.buf.len());
            assert!(size <= 2 * 45 + 30 + 30, "buffer {size} grew");
        }
        // Each round's work saw the window as it was before the round's read.
        assert_eq!(seen_ends[0], 0);
        assert!(seen_ends[1..]
            .iter()
            .enumerate()
            .all(|(k, &e)| e == 50 + 30 * (k as u64 + 1)));
        // Every held sample is still its own index after the compactions.
        let v = w.view();
        assert!((v.start()..v.end()).all(|i| re(&v, i) == Some(i as f32)));
    }

    #[test]
    fn read_during_runs_its_work_on_the_calling_thread_and_appends_the_read() {
        let mut src = Counter { next: 10, end: 100 };
        let mut w = SampleWindow::new();
        let caller = std::thread::current().id();
        let mut rounds = 0;
        loop {
            let before = w.end();
            let (got, same_thread) = w
                .read_during(&mut src, 40, || std::thread::current().id() == caller)
                .unwrap_or_else(|e| panic!("{e}"));
            assert!(same_thread, "the work left the calling thread");
            if got == 0 {
                break;
            }
            rounds += 1;
            if rounds > 1 {
                assert_eq!(w.end(), before + got as u64);
            }
        }
        // 90 samples in reads of 40, 40 and 10; the first adopted the source's index.
        assert_eq!(rounds, 3);
        assert_eq!((w.start(), w.end()), (10, 100));
        let v = w.view();
        assert!((v.start()..v.end()).all(|i| re(&v, i) == Some(i as f32)));
        assert!(w.end_of_stream());
        // At the end of the stream the work still runs.
        let (got, ran) = w
            .read_during(&mut src, 40, || true)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((got, ran), (0, true));
    }
}
