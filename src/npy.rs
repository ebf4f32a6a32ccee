//! NumPy `.npy` files for 2-D arrays: the format every analysis tool reads (`export` writes
//! them; `eval` and `train` read and write them).
//!
//! Writes version 1.0, little-endian float32, C order, header padded so the data starts on a
//! 64-byte boundary (what NumPy itself writes, so files can be memory-mapped). Reads float32
//! and, converting, float64 / int16 / int32 — the types reference DEMs arrive in.

use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

const MAGIC: &[u8] = b"\x93NUMPY";

/// What is wrong with an `.npy` file being read.
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    /// The file could not be opened or read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: io::Error,
    },
    /// The file is not a well-formed `.npy` file.
    #[error("{path} is not a valid .npy file: {reason}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A well-formed `.npy` file holding something other than a 2-D numeric array this
    /// reader converts.
    #[error("{path}: unsupported .npy array: {reason}")]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What is unsupported.
        reason: String,
    },
}

/// The header for a C-order little-endian float32 array of `shape`, padded with spaces and a
/// newline so magic + length + header is a multiple of 64 bytes.
fn header(shape: (usize, usize)) -> Vec<u8> {
    let dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({}, {}), }}", shape.0, shape.1);
    let unpadded = MAGIC.len() + 2 + 2 + dict.len() + 1;
    let total = unpadded.div_ceil(64) * 64;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&((total - MAGIC.len() - 4) as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out.resize(total - 1, b' ');
    out.push(b'\n');
    out
}

/// Streams an `.npy` file row by row, so exports larger than memory still work. The file
/// appears at its final path only when [`NpyWriter::finish`] succeeds.
pub(crate) struct NpyWriter {
    tmp: PathBuf,
    path: PathBuf,
    out: BufWriter<File>,
    remaining: usize,
    finished: bool,
}

impl Drop for NpyWriter {
    /// An abandoned export (error, Ctrl-C unwinding) leaves no half-written `.tmp` behind.
    fn drop(&mut self) {
        if !self.finished {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

impl NpyWriter {
    /// Starts `path` (written as `path.tmp` until finished) for an array of `shape`.
    pub(crate) fn create(path: &Path, shape: (usize, usize)) -> io::Result<NpyWriter> {
        let tmp = tmp_path(path);
        let out = BufWriter::new(File::create(&tmp)?);
        let mut w = NpyWriter { tmp, path: path.to_path_buf(), out, remaining: shape.0 * shape.1, finished: false };
        w.out.write_all(&header(shape))?;
        Ok(w)
    }

    /// Appends values in row-major order.
    pub(crate) fn write(&mut self, values: &[f32]) -> io::Result<()> {
        if values.len() > self.remaining {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, "more values than the array's shape holds"));
        }
        self.remaining -= values.len();
        let mut bytes = Vec::with_capacity(values.len() * 4);
        for v in values {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        self.out.write_all(&bytes)
    }

    /// Checks every value was written, flushes and moves the file into place.
    pub(crate) fn finish(mut self) -> io::Result<()> {
        if self.remaining != 0 {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, "fewer values than the array's shape holds"));
        }
        self.out.flush()?;
        self.out.get_ref().sync_all()?;
        std::fs::rename(&self.tmp, &self.path)?;
        self.finished = true;
        Ok(())
    }
}

/// `FILE` → `FILE.tmp`: the name a file is written under before it is complete.
pub(crate) fn tmp_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(".tmp");
    PathBuf::from(s)
}

/// Writes a 2-D float32 array (row-major, `shape` = (rows, columns)) to `path`, atomically.
pub fn write_npy_f32(path: &Path, shape: (usize, usize), data: &[f32]) -> io::Result<()> {
    if data.len() != shape.0 * shape.1 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} values do not fill a {}x{} array", data.len(), shape.0, shape.1),
        ));
    }
    let mut w = NpyWriter::create(path, shape)?;
    w.write(data)?;
    w.finish()
}

/// Reads a 2-D C-order `.npy` array as float32: `((rows, columns), values row-major)`.
/// float64, int16 and int32 arrays are converted; anything else is refused with a reason.
pub fn read_npy_f32(path: &Path) -> Result<((usize, usize), Vec<f32>), NpyError> {
    let mut bytes = Vec::new();
    File::open(path)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .map_err(|source| NpyError::Io { path: path.to_path_buf(), source })?;
    let format = |reason: String| NpyError::Format { path: path.to_path_buf(), reason };
    let unsupported = |reason: String| NpyError::Unsupported { path: path.to_path_buf(), reason };

    if bytes.len() < MAGIC.len() + 2 || &bytes[..MAGIC.len()] != MAGIC {
        return Err(format("it does not start with the \\x93NUMPY magic".into()));
    }
    let major = bytes[MAGIC.len()];
    let (len_bytes, start) = match major {
        1 => (2, MAGIC.len() + 4),
        2 | 3 => (4, MAGIC.len() + 6),
        v => return Err(unsupported(format!("format version {v} (this reader knows 1, 2 and 3)"))),
    };
    if bytes.len() < start {
        return Err(format("the file ends inside the header length".into()));
    }
    let len_field = &bytes[MAGIC.len() + 2..start];
    let header_len = if len_bytes == 2 {
        u16::from_le_bytes([len_field[0], len_field[1]]) as usize
    } else {
        u32::from_le_bytes([len_field[0], len_field[1], len_field[2], len_field[3]]) as usize
    };
    let data_start = start + header_len;
    if bytes.len() < data_start {
        return Err(format(format!("the header claims {header_len} bytes but the file ends first")));
    }
    let header = std::str::from_utf8(&bytes[start..data_start]).map_err(|_| format("the header is not text".into()))?;
    let header = parse_header(header).map_err(format)?;

    if header.fortran_order {
        return Err(unsupported("Fortran (column-major) order; save it with numpy.ascontiguousarray".into()));
    }
    let shape = match header.shape[..] {
        [h, w] => (h, w),
        _ => {
            return Err(unsupported(format!(
                "{}-D shape {:?}; a 2-D array is needed",
                header.shape.len(),
                header.shape
            )))
        }
    };
    let dtype = Dtype::parse(&header.descr)
        .ok_or_else(|| unsupported(format!("dtype '{}' (readable: '<f4', '<f8', '<i2', '<i4')", header.descr)))?;
    let count = shape.0.checked_mul(shape.1).ok_or_else(|| format(format!("shape {shape:?} is too large")))?;
    let expected = count.checked_mul(dtype.size()).ok_or_else(|| format(format!("shape {shape:?} is too large")))?;
    let data = &bytes[data_start..];
    if data.len() != expected {
        return Err(format(format!(
            "a {}x{} '{}' array needs {expected} data bytes, the file has {} (truncated or corrupt)",
            shape.0,
            shape.1,
            header.descr,
            data.len()
        )));
    }
    Ok((shape, dtype.decode(data)))
}

/// The element types this reader converts to float32.
#[derive(Clone, Copy, Debug)]
enum Dtype {
    F4,
    F8,
    I2,
    I4,
}

impl Dtype {
    /// From a NumPy `descr`; `|` (no byte order) only makes sense for 1-byte types, so only
    /// `<` and `=` are little-endian here (`=` is native, little-endian on every machine
    /// this runs on).
    fn parse(descr: &str) -> Option<Dtype> {
        let body = descr.strip_prefix('<').or_else(|| descr.strip_prefix('='))?;
        Some(match body {
            "f4" => Dtype::F4,
            "f8" => Dtype::F8,
            "i2" => Dtype::I2,
            "i4" => Dtype::I4,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Dtype::F4 | Dtype::I4 => 4,
            Dtype::F8 => 8,
            Dtype::I2 => 2,
        }
    }

    fn decode(self, data: &[u8]) -> Vec<f32> {
        match self {
            Dtype::F4 => data.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect(),
            Dtype::F8 => data
                .chunks_exact(8)
                .map(|b| f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]) as f32)
                .collect(),
            Dtype::I2 => data.chunks_exact(2).map(|b| i16::from_le_bytes([b[0], b[1]]) as f32).collect(),
            Dtype::I4 => data.chunks_exact(4).map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32).collect(),
        }
    }
}

/// The three keys of an `.npy` header dictionary.
#[derive(Debug, PartialEq)]
struct Header {
    descr: String,
    fortran_order: bool,
    shape: Vec<usize>,
}

/// Parses the Python-literal header dict, e.g.
/// `{'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }`.
fn parse_header(text: &str) -> Result<Header, String> {
    let text = text.trim();
    let body = text
        .strip_prefix('{')
        .and_then(|t| t.strip_suffix('}'))
        .ok_or_else(|| format!("the header is not a dictionary: {text:?}"))?;
    let value_of = |key: &str| -> Result<&str, String> {
        let at = body.find(&format!("'{key}'")).ok_or_else(|| format!("the header has no '{key}' key"))?;
        let rest = body[at + key.len() + 2..].trim_start();
        rest.strip_prefix(':').map(str::trim_start).ok_or_else(|| format!("no ':' after '{key}'"))
    };

    let descr = value_of("descr")?;
    let descr = descr
        .strip_prefix('\'')
        .and_then(|d| d.split('\'').next())
        .ok_or_else(|| "'descr' is not a quoted string (structured dtypes are not supported)".to_string())?
        .to_string();

    let order = value_of("fortran_order")?;
    let fortran_order = if order.starts_with("True") {
        true
    } else if order.starts_with("False") {
        false
    } else {
        return Err("'fortran_order' is neither True nor False".into());
    };

    let shape = value_of("shape")?;
    let inner = shape
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| "'shape' is not a tuple".to_string())?;
    let shape = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<usize>().map_err(|_| format!("shape entry '{s}' is not a size")))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Header { descr, fortran_order, shape })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An `.npy` file as NumPy would write it, for any dtype and payload.
    fn raw_npy(descr: &str, shape: &str, payload: &[u8]) -> Vec<u8> {
        let dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        let mut h = dict.into_bytes();
        while (10 + h.len() + 1) % 64 != 0 {
            h.push(b' ');
        }
        h.push(b'\n');
        let mut out = MAGIC.to_vec();
        out.extend_from_slice(&[1, 0]);
        out.extend_from_slice(&(h.len() as u16).to_le_bytes());
        out.extend_from_slice(&h);
        out.extend_from_slice(payload);
        out
    }

    #[test]
    fn round_trip_preserves_shape_and_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npy");
        let data: Vec<f32> = (0..12).map(|i| i as f32 * -1.5 + 0.25).collect();
        write_npy_f32(&path, (3, 4), &data).unwrap();
        assert_eq!(read_npy_f32(&path).unwrap(), ((3, 4), data));
        assert!(!tmp_path(&path).exists(), "the temporary file is renamed away");
    }

    #[test]
    fn header_is_numpy_v1_and_64_byte_aligned() {
        for shape in [(1, 1), (3, 4), (123_456, 7_890_123)] {
            let h = header(shape);
            assert_eq!(h.len() % 64, 0);
            assert_eq!(&h[..8], b"\x93NUMPY\x01\x00");
            assert_eq!(u16::from_le_bytes([h[8], h[9]]) as usize, h.len() - 10);
            assert_eq!(*h.last().unwrap(), b'\n');
            let text = std::str::from_utf8(&h[10..]).unwrap();
            let parsed = parse_header(text).unwrap();
            assert_eq!(parsed, Header { descr: "<f4".into(), fortran_order: false, shape: vec![shape.0, shape.1] });
        }
    }

    #[test]
    fn other_dtypes_are_converted() {
        let dir = tempfile::tempdir().unwrap();
        let cases: [(&str, Vec<u8>); 3] = [
            ("<f8", [1.5f64, -2.0].iter().flat_map(|v| v.to_le_bytes()).collect()),
            ("<i2", [1i16, -2].iter().flat_map(|v| v.to_le_bytes()).collect()),
            ("<i4", [1i32, -2].iter().flat_map(|v| v.to_le_bytes()).collect()),
        ];
        for (descr, payload) in cases {
            let path = dir.path().join("t.npy");
            std::fs::write(&path, raw_npy(descr, "(1, 2)", &payload)).unwrap();
            let (shape, values) = read_npy_f32(&path).unwrap();
            assert_eq!(shape, (1, 2), "{descr}");
            assert_eq!(values[1], -2.0, "{descr}");
        }
    }

    fn read_error(bytes: &[u8]) -> String {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("broken.npy");
        std::fs::write(&path, bytes).unwrap();
        let err = read_npy_f32(&path).unwrap_err().to_string();
        assert!(err.contains("broken.npy"), "error does not name the file: {err}");
        err
    }

    #[test]
    fn broken_files_are_refused_naming_the_file_and_the_fault() {
        assert!(read_error(b"").contains("magic"));
        assert!(read_error(b"PK\x03\x04 this is a zip").contains("magic"));
        let good = raw_npy("<f4", "(2, 2)", &[0u8; 16]);
        assert!(read_error(&good[..good.len() - 3]).contains("truncated"));
        assert!(read_error(&good[..20]).contains("header"));
        assert!(read_error(&raw_npy("<f4", "(4,)", &[0u8; 16])).contains("2-D"));
        assert!(read_error(&raw_npy(">f4", "(2, 2)", &[0u8; 16])).contains(">f4"));
        assert!(read_error(&raw_npy("<c8", "(2, 2)", &[0u8; 32])).contains("<c8"));
        let mut fortran = raw_npy("<f4", "(2, 2)", &[0u8; 16]);
        let at = fortran.windows(5).position(|w| w == b"False").unwrap();
        fortran[at..at + 5].copy_from_slice(b"True ");
        assert!(read_error(&fortran).contains("Fortran"));
    }

    #[test]
    fn missing_file_names_the_path() {
        let err = read_npy_f32(Path::new("/nonexistent/dir/x.npy")).unwrap_err().to_string();
        assert!(err.contains("/nonexistent/dir/x.npy"), "{err}");
    }

    #[test]
    fn wrong_value_count_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        assert!(write_npy_f32(&dir.path().join("a.npy"), (2, 2), &[1.0]).is_err());
        assert!(!dir.path().join("a.npy").exists());
    }
}
