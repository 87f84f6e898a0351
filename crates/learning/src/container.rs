//! The versioned binary container of exported weights.
//!
//! Layout: 8 magic bytes, a `u32` format version, a `u32` header length, the JSON header, a
//! `u64` value count, then that many little-endian `f32` values and nothing after them. Every
//! integer is little-endian.

use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;

/// A weights file that could not be read or written: which file, and the I/O error.
#[derive(Debug, thiserror::Error)]
#[error("cannot access weights file {path}")]
pub struct FileAccessError {
    /// The file.
    pub path: String,
    /// The I/O error.
    pub source: std::io::Error,
}

impl FileAccessError {
    /// The I/O error `source` met reading or writing `path`.
    pub fn new(path: &Path, source: std::io::Error) -> Self {
        FileAccessError {
            path: path.display().to_string(),
            source,
        }
    }
}

/// The bytes of the weights file at `path`.
pub fn read_file(path: &Path) -> Result<Vec<u8>, FileAccessError> {
    std::fs::read(path).map_err(|source| FileAccessError::new(path, source))
}

/// Why bytes are not a valid container; each crate maps these onto its own error type.
#[derive(Debug, thiserror::Error)]
pub enum ContainerError {
    /// The bytes do not start with the expected magic.
    #[error("missing the expected magic bytes")]
    BadMagic,
    /// The container was written by a layout version other than the one expected.
    #[error("format version {found} is not supported (expected {expected})")]
    UnsupportedVersion {
        /// Version the reader expects.
        expected: u32,
        /// Version in the bytes.
        found: u32,
    },
    /// The bytes end inside the part named.
    #[error("truncated: it ends inside the {part} ({expected} bytes needed, {found} present)")]
    Truncated {
        /// `header` (magic, version, lengths, JSON header, count) or `values`.
        part: &'static str,
        /// Bytes needed up to the end of the field being read.
        expected: usize,
        /// Bytes present.
        found: usize,
    },
    /// The JSON header does not parse into the header type.
    #[error("header is not valid: {0}")]
    BadHeader(String),
    /// The declared value count differs from the count the header implies.
    #[error("holds {found} values but the header needs {expected}")]
    CountMismatch {
        /// Values the header implies.
        expected: usize,
        /// Values declared.
        found: usize,
    },
    /// Bytes follow the last value.
    #[error("{0} unexpected bytes after the values")]
    TrailingBytes(usize),
}

/// The container bytes of `header` and `values` under `magic` and `version`.
///
/// # Panics
///
/// If `header` does not serialise to JSON (a bug in the header type) or is longer than
/// `u32::MAX` bytes.
pub fn encode<H: Serialize>(magic: &[u8; 8], version: u32, header: &H, values: &[f32]) -> Vec<u8> {
    let header = serde_json::to_vec(header).expect("header serialises");
    let header_len = u32::try_from(header.len()).expect("header fits a u32 length");
    let mut bytes = Vec::with_capacity(24 + header.len() + 4 * values.len());
    bytes.extend_from_slice(magic);
    bytes.extend_from_slice(&version.to_le_bytes());
    bytes.extend_from_slice(&header_len.to_le_bytes());
    bytes.extend_from_slice(&header);
    bytes.extend_from_slice(&(values.len() as u64).to_le_bytes());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes
}

/// Parses container bytes, accepting whatever value count they declare.
pub fn decode<H: DeserializeOwned>(
    bytes: &[u8],
    magic: &[u8; 8],
    version: u32,
) -> Result<(H, Vec<f32>), ContainerError> {
    decode_impl(bytes, magic, version, |_: &H| None)
}

/// Parses container bytes, failing with [`ContainerError::CountMismatch`] (before the values
/// are read) unless the declared value count equals `expected_count(&header)`.
pub fn decode_checked<H: DeserializeOwned>(
    bytes: &[u8],
    magic: &[u8; 8],
    version: u32,
    expected_count: impl FnOnce(&H) -> usize,
) -> Result<(H, Vec<f32>), ContainerError> {
    decode_impl(bytes, magic, version, |header: &H| {
        Some(expected_count(header))
    })
}

fn decode_impl<H: DeserializeOwned>(
    bytes: &[u8],
    magic: &[u8; 8],
    version: u32,
    expected_count: impl FnOnce(&H) -> Option<usize>,
) -> Result<(H, Vec<f32>), ContainerError> {
    let mut cursor = Cursor { bytes, at: 0 };
    if cursor.take(8, "header")? != magic {
        return Err(ContainerError::BadMagic);
    }
    let found = u32::from_le_bytes(cursor.array::<4>("header")?);
    if found != version {
        return Err(ContainerError::UnsupportedVersion {
            expected: version,
            found,
        });
    }
    let header_len = u32::from_le_bytes(cursor.array::<4>("header")?) as usize;
    let header: H = serde_json::from_slice(cursor.take(header_len, "header")?)
        .map_err(|e| ContainerError::BadHeader(e.to_string()))?;
    let count =
        usize::try_from(u64::from_le_bytes(cursor.array::<8>("header")?)).unwrap_or(usize::MAX);
    if let Some(expected) = expected_count(&header)
        && count != expected
    {
        return Err(ContainerError::CountMismatch {
            expected,
            found: count,
        });
    }
    let values = cursor
        .take(count.saturating_mul(4), "values")?
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    let rest = bytes.len() - cursor.at;
    if rest != 0 {
        return Err(ContainerError::TrailingBytes(rest));
    }
    Ok((header, values))
}

struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize, part: &'static str) -> Result<&'a [u8], ContainerError> {
        let end = self.at.saturating_add(n);
        if end > self.bytes.len() {
            return Err(ContainerError::Truncated {
                part,
                expected: end,
                found: self.bytes.len(),
            });
        }
        let slice = &self.bytes[self.at..end];
        self.at = end;
        Ok(slice)
    }

    fn array<const N: usize>(&mut self, part: &'static str) -> Result<[u8; N], ContainerError> {
        Ok(self.take(N, part)?.try_into().expect("N bytes"))
    }
}
