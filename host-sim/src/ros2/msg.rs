//! The ROS 2 message types the output uses, written out by hand (the ROS 2 client crate ships
//! none), and their CDR encoding.
//!
//! The field order and types are those of the message definitions ([`JOINT_STATE_DEFINITION`],
//! the text an MCAP file carries as its schema): `serde` serializes the structs field by field
//! in declaration order, which is what the DDS path relies on, and [`JointState::to_cdr`]
//! writes the same bytes for MCAP without a serializer crate.
//!
//! **CDR** (the OMG's classic encoding, XCDR1, which ROS 2 uses): a 4-byte encapsulation
//! header (`00 01 00 00`: little-endian CDR), then each primitive at an offset, counted from
//! after the header, that is a multiple of its size (`int32` 4, `float64` 8); a string is its
//! byte length including a closing NUL as `uint32`, the bytes and the NUL; a sequence is its
//! element count as `uint32` and the elements. An empty `float64[]` gets no padding (there is
//! no element to align), as eProsima Fast-CDR and RustDDS write it. Nothing here panics or
//! fails: encoding into a `Vec` cannot.

use serde::{Deserialize, Serialize};

/// `builtin_interfaces/msg/Time`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, `0..1_000_000_000`.
    pub nanosec: u32,
}

impl Time {
    /// The time `nanos` nanoseconds after the epoch of its clock (negative times and times
    /// past `i32::MAX` seconds saturate).
    pub fn from_nanos(nanos: i64) -> Self {
        let sec = nanos.div_euclid(1_000_000_000);
        let nanosec = nanos.rem_euclid(1_000_000_000) as u32;
        match i32::try_from(sec) {
            Ok(sec) if sec >= 0 => Self { sec, nanosec },
            _ if sec < 0 => Self::default(),
            _ => Self {
                sec: i32::MAX,
                nanosec: 999_999_999,
            },
        }
    }

    /// Nanoseconds since the clock's epoch.
    pub fn nanos(&self) -> i64 {
        self.sec as i64 * 1_000_000_000 + self.nanosec as i64
    }
}

/// `std_msgs/msg/Header`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// When the data was valid (here: on the audio clock).
    pub stamp: Time,
    /// The coordinate frame (empty for joint states).
    pub frame_id: String,
}

/// `sensor_msgs/msg/JointState`: positions in radians for revolute joints; `velocity` and
/// `effort` are left empty, which the message definition allows.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JointState {
    /// Header.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions (rad), one per name.
    pub position: Vec<f64>,
    /// Velocities (rad/s): empty.
    pub velocity: Vec<f64>,
    /// Efforts: empty.
    pub effort: Vec<f64>,
}

/// The ROS 2 type name of [`JointState`].
pub const JOINT_STATE_TYPE: &str = "sensor_msgs/msg/JointState";

/// The definition of [`JointState`] with its dependencies, in the `ros2msg` schema form an
/// MCAP file carries (the `.msg` text, then each used type after a line of 80 `=` and
/// `MSG: <type>`), comments left out.
pub const JOINT_STATE_DEFINITION: &str = "\
std_msgs/Header header
string[] name
float64[] position
float64[] velocity
float64[] effort
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
";

/// A little-endian CDR writer (see the module docs).
struct Cdr {
    buf: Vec<u8>,
}

impl Cdr {
    fn new() -> Self {
        Self {
            buf: vec![0x00, 0x01, 0x00, 0x00],
        }
    }

    fn align(&mut self, n: usize) {
        while !(self.buf.len() - 4).is_multiple_of(n) {
            self.buf.push(0);
        }
    }

    fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    fn string(&mut self, s: &str) {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    fn f64s(&mut self, v: &[f64]) {
        self.u32(v.len() as u32);
        for &x in v {
            self.f64(x);
        }
    }
}

impl JointState {
    /// The message as CDR bytes, encapsulation header included (see the module docs).
    pub fn to_cdr(&self) -> Vec<u8> {
        let mut w = Cdr::new();
        w.i32(self.header.stamp.sec);
        w.u32(self.header.stamp.nanosec);
        w.string(&self.header.frame_id);
        w.u32(self.name.len() as u32);
        for n in &self.name {
            w.string(n);
        }
        w.f64s(&self.position);
        w.f64s(&self.velocity);
        w.f64s(&self.effort);
        w.buf
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_split_into_seconds_and_nanoseconds() {
        assert_eq!(
            Time::from_nanos(1_500_000_001),
            Time {
                sec: 1,
                nanosec: 500_000_001
            }
        );
        assert_eq!(Time::from_nanos(-5), Time::default());
        assert_eq!(Time::from_nanos(i64::MAX).sec, i32::MAX);
        assert_eq!(Time::from_nanos(33_333_333).nanos(), 33_333_333);
    }

    /// Golden bytes, worked out by hand from the rules in the module docs.
    #[test]
    fn joint_state_cdr_bytes_are_pinned() {
        let m = JointState {
            header: Header {
                stamp: Time { sec: 1, nanosec: 2 },
                frame_id: String::new(),
            },
            name: vec!["ab".into()],
            position: vec![1.0],
            velocity: Vec::new(),
            effort: Vec::new(),
        };
        #[rustfmt::skip]
        let want: Vec<u8> = vec![
            0x00, 0x01, 0x00, 0x00,             // CDR little-endian
            1, 0, 0, 0,                         // sec            @0
            2, 0, 0, 0,                         // nanosec        @4
            1, 0, 0, 0, 0,                      // frame_id: "" + NUL @8
            0, 0, 0,                            // pad to 16
            1, 0, 0, 0,                         // name: 1 string @16
            3, 0, 0, 0, b'a', b'b', 0,          // "ab" + NUL     @20
            0,                                  // pad to 28
            1, 0, 0, 0,                         // position: 1    @28
            0, 0, 0, 0, 0, 0, 0xf0, 0x3f,       // 1.0 at 32 (8-aligned)
            0, 0, 0, 0,                         // velocity: 0    @40
            0, 0, 0, 0,                         // effort: 0      @44
        ];
        assert_eq!(m.to_cdr(), want);
    }
}
