//! A bounded read-ahead buffer over a file, addressed by absolute byte offset (`u64`).
//!
//! Sources ask for byte ranges that move forward through the file; each request is served from
//! the buffer when it can be, else the buffer is refilled (keeping any overlap) with one large
//! read. Memory stays at [`CHUNK_BYTES`] whatever the file's length.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::PathBuf;

use crate::error::SampleError;

/// Size of the read-ahead buffer (1 MiB).
pub const CHUNK_BYTES: usize = 1 << 20;

/// Read-ahead buffer over `file`, never reading at or beyond `limit` (the end of the data).
#[derive(Debug)]
pub(crate) struct ChunkReader {
    file: File,
    path: PathBuf,
    buf: Vec<u8>,
    /// File offset of `buf[0]`.
    buf_start: u64,
    /// Valid bytes in `buf`.
    buf_len: usize,
    /// Where the file cursor is.
    file_pos: u64,
    /// End of the readable data.
    limit: u64,
}

impl ChunkReader {
    pub fn new(file: File, path: PathBuf, limit: u64) -> Self {
        ChunkReader {
            file,
            path,
            buf: vec![0; CHUNK_BYTES],
            buf_start: 0,
            buf_len: 0,
            file_pos: 0,
            limit,
        }
    }

    /// The bytes `start..start + len` (`len <= CHUNK_BYTES`, `start + len <= limit`).
    /// Fills `dst` with the bytes from `start` on: what the chunk holds of them is copied,
    /// the rest read from the file straight into `dst` (no second copy for large reads). An
    /// error if the file ends first.
    pub fn read_into(&mut self, start: u64, dst: &mut [u8]) -> Result<(), SampleError> {
        let buf_end = self.buf_start + self.buf_len as u64;
        let mut done = 0;
        if start >= self.buf_start && start < buf_end {
            let off = (start - self.buf_start) as usize;
            done = (self.buf_len - off).min(dst.len());
            dst[..done].copy_from_slice(&self.buf[off..off + done]);
        }
        if done == dst.len() {
            return Ok(());
        }
        // The chunk is left behind: empty it, and read the rest in place.
        self.buf_len = 0;
        let read_at = start + done as u64;
        self.buf_start = read_at;
        if self.file_pos != read_at {
            self.file
                .seek(SeekFrom::Start(read_at))
                .map_err(|e| SampleError::io("seek in", &self.path, e))?;
            self.file_pos = read_at;
        }
        let want = dst.len() as u64;
        if read_at + (want - done as u64) > self.limit {
            return Err(truncated(&self.path, read_at, start + want));
        }
        while done < dst.len() {
            match self.file.read(&mut dst[done..]) {
                Ok(0) => return Err(truncated(&self.path, start + done as u64, start + want)),
                Ok(n) => {
                    done += n;
                    self.file_pos += n as u64;
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(SampleError::io("read", &self.path, e)),
            }
        }
        self.buf_start = self.file_pos;
        Ok(())
    }

    pub fn get(&mut self, start: u64, len: usize) -> Result<&[u8], SampleError> {
        let buf_end = self.buf_start + self.buf_len as u64;
        if start >= self.buf_start && start + len as u64 <= buf_end {
            let off = (start - self.buf_start) as usize;
            return Ok(&self.buf[off..off + len]);
        }
        if start >= self.buf_start && start < buf_end {
            let off = (start - self.buf_start) as usize;
            self.buf.copy_within(off..self.buf_len, 0);
            self.buf_len -= off;
        } else {
            self.buf_len = 0;
        }
        self.buf_start = start;
        let fill_to = (self.limit.saturating_sub(start)).min(CHUNK_BYTES as u64) as usize;
        let read_at = start + self.buf_len as u64;
        if self.file_pos != read_at {
            self.file
                .seek(SeekFrom::Start(read_at))
                .map_err(|e| SampleError::io("seek in", &self.path, e))?;
            self.file_pos = read_at;
        }
        while self.buf_len < fill_to {
            match self.file.read(&mut self.buf[self.buf_len..fill_to]) {
                Ok(0) => break,
                Ok(n) => {
                    self.buf_len += n;
                    self.file_pos += n as u64;
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(SampleError::io("read", &self.path, e)),
            }
        }
        if self.buf_len < len {
            return Err(truncated(
                &self.path,
                start + self.buf_len as u64,
                start + len as u64,
            ));
        }
        Ok(&self.buf[..len])
    }
}

/// The file ended at byte `at` where `expected` bytes were due.
fn truncated(path: &std::path::Path, at: u64, expected: u64) -> SampleError {
    SampleError::io(
        "read",
        path,
        std::io::Error::new(
            std::io::ErrorKind::UnexpectedEof,
            format!(
                "file ended at byte {at} but {expected} bytes were expected: was it truncated while reading?"
            ),
        ),
    )
}
