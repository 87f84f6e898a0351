//! The weights container: round trip and every rejection.

use emg_learning::container::{decode, decode_checked, encode};
use emg_learning::{Backend, ContainerError};
use serde::{Deserialize, Serialize};

const MAGIC: &[u8; 8] = b"TESTMAGC";

#[derive(Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    name: String,
    len: usize,
}

fn sample() -> (Header, Vec<f32>, Vec<u8>) {
    let header = Header {
        name: "tiny".into(),
        len: 3,
    };
    let values = vec![1.5, -0.25, f32::MIN_POSITIVE];
    let bytes = encode(MAGIC, 7, &header, &values);
    (header, values, bytes)
}

#[test]
fn round_trip_is_exact_and_laid_out_as_documented() {
    let (header, values, bytes) = sample();
    let json = serde_json::to_vec(&header).unwrap();
    assert_eq!(&bytes[..8], MAGIC);
    assert_eq!(bytes[8..12], 7u32.to_le_bytes());
    assert_eq!(bytes[12..16], (json.len() as u32).to_le_bytes());
    assert_eq!(&bytes[16..16 + json.len()], json.as_slice());
    assert_eq!(bytes.len(), 16 + json.len() + 8 + 4 * values.len());
    let (h, v): (Header, Vec<f32>) = decode(&bytes, MAGIC, 7).unwrap();
    assert_eq!(h, header);
    assert_eq!(v, values);
    let (_, v): (Header, Vec<f32>) = decode_checked(&bytes, MAGIC, 7, |h: &Header| h.len).unwrap();
    assert_eq!(v, values);
}

#[test]
fn empty_values_round_trip() {
    let bytes = encode(MAGIC, 1, &(), &[]);
    let ((), values): ((), Vec<f32>) = decode(&bytes, MAGIC, 1).unwrap();
    assert!(values.is_empty());
}

#[test]
fn bad_magic_is_rejected() {
    let (_, _, mut bytes) = sample();
    bytes[0] ^= 0xff;
    assert!(matches!(
        decode::<Header>(&bytes, MAGIC, 7),
        Err(ContainerError::BadMagic)
    ));
    assert!(matches!(
        decode::<Header>(&bytes[..3], MAGIC, 7),
        Err(ContainerError::Truncated {
            part: "header",
            expected: 8,
            found: 3
        })
    ));
}

#[test]
fn wrong_version_is_rejected() {
    let (_, _, bytes) = sample();
    assert!(matches!(
        decode::<Header>(&bytes, MAGIC, 8),
        Err(ContainerError::UnsupportedVersion {
            expected: 8,
            found: 7
        })
    ));
}

#[test]
fn truncation_names_the_part() {
    let (_, _, bytes) = sample();
    for cut in 0..bytes.len() {
        let error = decode::<Header>(&bytes[..cut], MAGIC, 7).unwrap_err();
        let values_start = bytes.len() - 12;
        let expected_part = if cut < values_start {
            "header"
        } else {
            "values"
        };
        assert!(
            matches!(error, ContainerError::Truncated { part, found, .. } if part == expected_part && found == cut),
            "cut at {cut}: {error}"
        );
    }
}

#[test]
fn trailing_bytes_are_rejected() {
    let (_, _, mut bytes) = sample();
    bytes.extend_from_slice(&[0, 0]);
    assert!(matches!(
        decode::<Header>(&bytes, MAGIC, 7),
        Err(ContainerError::TrailingBytes(2))
    ));
}

#[test]
fn bad_header_and_count_mismatch_are_rejected() {
    let (_, _, bytes) = sample();
    assert!(matches!(
        decode::<Vec<u8>>(&bytes, MAGIC, 7),
        Err(ContainerError::BadHeader(_))
    ));
    // The count check comes before the values are read, so it wins over truncation.
    let cut = &bytes[..bytes.len() - 4];
    assert!(matches!(
        decode_checked(cut, MAGIC, 7, |_: &Header| 5),
        Err(ContainerError::CountMismatch {
            expected: 5,
            found: 3
        })
    ));
}

#[test]
fn backend_names_and_serde_agree() {
    assert_eq!(Backend::default(), Backend::Flex);
    for backend in [Backend::Flex, Backend::Ndarray] {
        let json = serde_json::to_string(&backend).unwrap();
        assert_eq!(json, format!("\"{}\"", backend.name()));
        assert_eq!(serde_json::from_str::<Backend>(&json).unwrap(), backend);
    }
}
