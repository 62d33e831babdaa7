// The replay harness of battgen's Rust crate: the Python tests append one test per message, whose
// cases are what battgen's generated Python package makes of every conformance vector record
// (tests/rust_cases.py). Each case must give the same bytes, values and problems here.

use battgen::mavlink_wire::{self, DecodeError, Header};
use battgen::{dronecan_wire, uorb_wire, Problems, Validate};
use core::fmt::Debug;

// A case: its id, the value given (floats rounded to f32) with its problems (when Rust holds the
// Python record exactly), the value decoded from the Python encoding, the Python encoding, and the
// problems of the decoded value.
type ProblemList = &'static [&'static str];
type Given<M> = (&'static str, M, Option<ProblemList>, M);
/// (id, value, its problems, decoded, payload, frame, frame sequence number, the MAVLink 1 frame and
/// what it decodes to (message ids below 256), the frame signed, problems)
type MavlinkCase<M> = (
    Given<M>,
    &'static [u8],
    &'static [u8],
    u8,
    Option<(&'static [u8], M)>,
    &'static [u8],
    ProblemList,
);
/// (id, value, its problems, decoded, struct bytes, problems)
type UorbCase<M> = (Given<M>, &'static [u8], ProblemList);
/// (id, value, its problems, decoded, payload with the tail array optimisation, without (CAN FD), problems)
type DronecanCase<M> = (Given<M>, &'static [u8], &'static [u8], ProblemList);
/// (id, value, problems): a message whose codec the crate does not have yet
type ValuesCase<M> = (&'static str, M, &'static [&'static str]);

/// The problems as the Python validators name them: `path rule`.
fn problems<T: Validate>(value: &T) -> Vec<String> {
    let mut out = Problems::<1024>::new();
    value.validate_into(&mut out);
    assert_eq!(out.dropped(), 0);
    out.as_slice()
        .iter()
        .map(|p| match p.index {
            Some(i) => format!("{}[{}] {}", p.field, i, p.rule),
            None => format!("{} {}", p.field, p.rule),
        })
        .collect()
}

fn check_problems<T: Validate>(id: &str, value: &T, expected: &[&str]) {
    let found = problems(value);
    assert_eq!(found, expected, "{id}: problems");
}

fn check_given<T: Validate>(id: &str, value: &T, given: Option<ProblemList>) {
    if let Some(expected) = given {
        assert_eq!(problems(value), expected, "{id}: problems of the value given");
    }
}

fn replay_mavlink<M>(cases: &[MavlinkCase<M>], count: usize)
where
    M: mavlink_wire::Message + Validate + PartialEq + Debug,
{
    assert_eq!(cases.len(), count);
    for ((id, value, given, decoded), payload, frame, seq, v1, signed, expected) in cases {
        check_given(id, value, *given);
        let mut buf = [0u8; 255];
        let n = value.encode(&mut buf);
        assert_eq!(&buf[..n], *payload, "{id}: payload");
        assert_eq!(M::decode(payload).as_ref(), Ok(decoded), "{id}: decoded payload");

        let header = Header {
            seq: *seq,
            sysid: 1,
            compid: 1,
        };
        let mut out = [0u8; mavlink_wire::MAX_FRAME_LENGTH];
        let n = mavlink_wire::encode_frame(value, header, &mut out);
        assert_eq!(&out[..n], *frame, "{id}: frame");
        let (got_header, got) = mavlink_wire::decode_frame::<M>(frame).expect(id);
        assert_eq!((got_header, &got), (header, decoded), "{id}: decoded frame");

        let (got_header, got) = mavlink_wire::decode_frame::<M>(signed).expect(id);
        assert_eq!((got_header, &got), (header, decoded), "{id}: decoded signed frame");
        match v1 {
            Some((frame_v1, decoded_v1)) => {
                let n = mavlink_wire::encode_frame_v1(value, header, &mut out).expect(id);
                assert_eq!(&out[..n], *frame_v1, "{id}: MAVLink 1 frame");
                let (got_header, got) = mavlink_wire::decode_frame::<M>(frame_v1).expect(id);
                assert_eq!((got_header, &got), (header, decoded_v1), "{id}: decoded MAVLink 1 frame");
            }
            None => assert_eq!(mavlink_wire::encode_frame_v1(value, header, &mut out), None),
        }

        // one bit flipped in the payload: the checksum must catch it
        let mut bad = frame.to_vec();
        bad[mavlink_wire::HEADER_LENGTH] ^= 0x01;
        assert!(
            matches!(mavlink_wire::decode_frame::<M>(&bad), Err(DecodeError::BadCrc { .. })),
            "{id}: corrupted frame accepted"
        );
        check_problems(id, decoded, expected);
    }
}

fn replay_uorb<M>(cases: &[UorbCase<M>], count: usize)
where
    M: uorb_wire::Message + Validate + PartialEq + Debug,
{
    assert_eq!(cases.len(), count);
    for ((id, value, given, decoded), data, expected) in cases {
        check_given(id, value, *given);
        let mut buf = vec![0xAAu8; M::STRUCT_SIZE];
        value.encode(&mut buf);
        assert_eq!(&buf[..], *data, "{id}: struct bytes");
        assert_eq!(M::decode(data).as_ref(), Ok(decoded), "{id}: decoded struct");
        check_problems(id, decoded, expected);
    }
}

fn replay_dronecan<M>(cases: &[DronecanCase<M>], count: usize)
where
    M: dronecan_wire::Message + Validate + PartialEq + Debug,
{
    assert_eq!(cases.len(), count);
    for ((id, value, given, decoded), payload, fd, expected) in cases {
        check_given(id, value, *given);
        for (tao, bytes) in [(true, payload), (false, fd)] {
            let mut buf = vec![0xAAu8; M::MAX_BYTES];
            let n = value.encode(&mut buf, tao).expect(id);
            assert_eq!(&buf[..n], *bytes, "{id}: payload (tao {tao})");
            assert_eq!(M::decode(bytes, tao).as_ref(), Ok(decoded), "{id}: decoded (tao {tao})");
        }
        check_problems(id, decoded, expected);
    }
}

#[allow(dead_code)] // used when a message without a codec is replayed
fn replay_values<M: Validate>(cases: &[ValuesCase<M>], count: usize) {
    assert_eq!(cases.len(), count);
    for (id, value, expected) in cases {
        check_problems(id, value, expected);
    }
}

