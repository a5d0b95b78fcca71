//! The one binary format of saved states (integrator snapshots and FMU states): postcard, a
//! documented and stable serde wire format, behind a header of an 8-byte magic and a format
//! version, so a foreign or outdated buffer is refused before its body is decoded, and followed
//! by the SHA-256 of the body, so that a buffer changed after it was written (a flipped bit, a
//! truncated copy) is refused instead of decoded into plausible but wrong numbers.
//!
//! Lengths inside the body come from the buffer; serde preallocates cautiously (at most about
//! 1 MiB per sequence), so a forged length cannot make decoding allocate more than the buffer
//! describes. Each body type checks its own invariants after decoding.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// Length of the checksum after the body.
const CHECKSUM_BYTES: usize = 32;

#[derive(Serialize, Deserialize)]
struct Header {
    magic: [u8; 8],
    version: u32,
}

/// `magic`, `version`, `body`, then the SHA-256 of the body.
pub fn encode<T: Serialize>(magic: &[u8; 8], version: u32, body: &T) -> Vec<u8> {
    let header = Header {
        magic: *magic,
        version,
    };
    let mut bytes = postcard::to_stdvec(&header).expect("a header always serialises");
    // Serialising plain data (numbers, vectors, strings, options) into memory cannot fail.
    let body = postcard::to_stdvec(body).expect("a saved state always serialises");
    let checksum = Sha256::digest(&body);
    bytes.extend(body);
    bytes.extend_from_slice(&checksum);
    bytes
}

/// The body of a buffer written by [`encode`] with the same magic and version. `what` names the
/// buffer in messages.
pub fn decode<T: DeserializeOwned>(
    bytes: &[u8],
    magic: &[u8; 8],
    version: u32,
    what: &str,
) -> Result<T, String> {
    let (header, rest) = postcard::take_from_bytes::<Header>(bytes)
        .map_err(|_| format!("{} bytes are too short for {what}", bytes.len()))?;
    if &header.magic != magic {
        return Err(format!("not {what} (wrong magic)"));
    }
    if header.version != version {
        return Err(format!(
            "{what} has format version {}, expected {version}",
            header.version
        ));
    }
    let Some(split) = rest.len().checked_sub(CHECKSUM_BYTES) else {
        return Err(format!("{what} is truncated (no checksum)"));
    };
    let (rest, checksum) = rest.split_at(split);
    if Sha256::digest(rest).as_slice() != checksum {
        return Err(format!(
            "damaged {what}: its checksum does not match (changed or truncated after it was written)"
        ));
    }
    let (body, trailing) =
        postcard::take_from_bytes::<T>(rest).map_err(|e| format!("damaged {what}: {e}"))?;
    if !trailing.is_empty() {
        return Err(format!("{} trailing bytes after {what}", trailing.len()));
    }
    Ok(body)
}

/// Serde for a dense `faer::Mat<f64>`: rows, columns and the column-major values.
pub mod dense_matrix {
    use faer::Mat;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `m` as (rows, columns, column-major values).
    pub fn serialize<S: Serializer>(m: &Mat<f64>, s: S) -> Result<S::Ok, S::Error> {
        let values: Vec<f64> = (0..m.ncols())
            .flat_map(|j| m.col(j).iter().copied().collect::<Vec<_>>())
            .collect();
        (m.nrows(), m.ncols(), values).serialize(s)
    }

    /// Reads a matrix written by [`serialize`]; refused if the number of values is not rows ×
    /// columns.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Mat<f64>, D::Error> {
        let (rows, cols, values) = <(usize, usize, Vec<f64>)>::deserialize(d)?;
        if rows.checked_mul(cols) != Some(values.len()) {
            return Err(serde::de::Error::custom(format!(
                "a {rows} x {cols} matrix with {} values",
                values.len()
            )));
        }
        Ok(Mat::from_fn(rows, cols, |i, j| values[i + j * rows]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_trailing_bytes_are_checked() {
        let bytes = encode(b"TESTTEST", 7, &(1.5f64, vec![1u32, 2, 3]));
        let ok: (f64, Vec<u32>) = decode(&bytes, b"TESTTEST", 7, "a test value").unwrap();
        assert_eq!(ok, (1.5, vec![1, 2, 3]));
        let wrong_magic = decode::<(f64, Vec<u32>)>(&bytes, b"OTHERMAG", 7, "x").unwrap_err();
        assert!(wrong_magic.contains("magic"), "{wrong_magic}");
        let wrong_version = decode::<(f64, Vec<u32>)>(&bytes, b"TESTTEST", 8, "x").unwrap_err();
        assert!(wrong_version.contains("version 7"), "{wrong_version}");
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode::<(f64, Vec<u32>)>(&longer, b"TESTTEST", 7, "x")
            .unwrap_err()
            .contains("checksum"));
        for cut in 0..bytes.len() {
            assert!(decode::<(f64, Vec<u32>)>(&bytes[..cut], b"TESTTEST", 7, "x").is_err());
        }
    }

    /// Issue 28: every bit flip of a scene-2 FMU state was accepted.
    #[test]
    fn every_flipped_bit_is_refused() {
        let bytes = encode(
            b"TESTTEST",
            7,
            &(1.5f64, vec![1u32, 2, 3], "text".to_owned()),
        );
        for i in 0..bytes.len() * 8 {
            let mut flipped = bytes.clone();
            flipped[i / 8] ^= 1 << (i % 8);
            let result = decode::<(f64, Vec<u32>, String)>(&flipped, b"TESTTEST", 7, "x");
            assert!(result.is_err(), "bit {i} flipped was accepted");
        }
    }

    #[test]
    fn matrices_round_trip_bit_for_bit() {
        #[derive(Serialize, Deserialize)]
        struct Holder(#[serde(with = "dense_matrix")] faer::Mat<f64>);
        let m = faer::Mat::from_fn(3, 2, |i, j| (i as f64 + 0.1) / (j as f64 + 0.3));
        let bytes = postcard::to_stdvec(&Holder(m.clone())).unwrap();
        let back: Holder = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(back.0, m);
        // A declared size the values do not fill is refused.
        let forged = postcard::to_stdvec(&(1usize << 40, 1usize << 40, vec![0.0f64])).unwrap();
        assert!(postcard::from_bytes::<Holder>(&forged).is_err());
    }
}
