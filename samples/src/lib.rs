//! IF samples for gpsrx: sample formats (read and write), SigMF and WAV files, streaming sample
//! sources, recording statistics, and the GPS L1 C/A signal simulator.
//!
//! - [`format`](mod@format): the sample formats and their names (table there);
//! - [`source`]: [`source::open_source`] streams complex baseband from any recording;
//! - [`stream_source`]: [`ReaderSource`] reads standard input, a pipe or any `std::io::Read`;
//! - [`writer`]: [`writer::create_writer`] / [`writer::create_wav_writer`];
//! - [`sigmf`]: `.sigmf-meta` read/write; [`wav`]: WAV layout;
//! - [`info`]: statistics, histogram and spectrum of a recording (`gpsrx info`).

pub mod capture_gaps;
mod chunk;
mod codec;
pub mod error;
pub mod file_source;
pub mod format;
pub mod info;
mod info_notes;
mod info_text;
pub mod mixer;
pub mod resolve;
pub mod sigmf;
pub mod sim;
pub mod source;
pub mod span;
mod spectrum;
pub mod stream_source;
pub mod wav;
pub mod writer;

pub use error::SampleError;
pub use format::SampleFormat;
pub use source::{
    held_gain, open_source, quantize_to_ci16, IntegerFormat, IntegerSamplesMut, SampleSource,
    SourceConfig,
};
pub use stream_source::ReaderSource;
pub use writer::{create_wav_writer, create_writer, SampleWriter, WriteStats};
