//! Robots through ROS 2: the character's joints as `sensor_msgs/msg/JointState`, live over
//! DDS ([`Publisher`], feature `ros2`), recorded in an MCAP file ([`recording`]), and the
//! character as a URDF ([`urdf`]) so `robot_state_publisher`, RViz and Foxglove show the
//! motion on its skeleton (docs/ros2.md).
//!
//! **What a message holds** ([`JointStream`]): one message per animation tick; `name` is the
//! blob's channels in blob order (a full-skeleton blob: `<joint>.<axis>rotation` for every
//! rotation channel of the library's skeleton; a puppet blob: the rig's channels), `position`
//! the angle each servo of the runtime's `ServoRig` is commanded to, in radians: the played
//! pose within the rig's limits and slew rate (the blob's calibration, or `--rig`'s). For a
//! full-skeleton blob, whose calibration has no effective limit, that is the played pose
//! itself. The stamp is the tick's time on the audio clock (`tick / fps`), plus an offset the
//! caller chooses: 0 for a recording, the wall-clock time the audio started for live DDS.
//!
//! **Checked once.** A topic name and `ROS_DOMAIN_ID` are validated here ([`topic_name`],
//! [`domain_id`]) before anything starts; after that, publishing fails only if the network
//! does.
//!
//! - [`msg`]: the message types, their definition text and CDR bytes.
//! - [`Ros2Error`]: why ROS 2 output could not start or go on.
//! - [`topic_name`], [`domain_id`], [`full_topic`], [`QOS`]: where the messages go and how.
//! - [`recording`]: the MCAP file.
//! - [`urdf`]: the character as a URDF, its joints named as the messages name them.

mod error;
pub mod msg;
pub mod recording;
mod topic;
pub mod urdf;

#[cfg(feature = "ros2")]
mod dds;

use gesture_runtime::blob::Blob;

pub use error::Ros2Error;
use msg::{Header, JointState, Time};
pub use topic::{domain_id, full_topic, topic_name, DEFAULT_TOPIC, QOS};

/// The messages of one character: its joint names and frame rate (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct JointStream {
    names: Vec<String>,
    fps: f64,
}

impl JointStream {
    /// The stream of `blob`'s channels.
    pub fn new(blob: &Blob<'_>) -> Self {
        Self {
            names: blob.channel_names().map(str::to_string).collect(),
            fps: blob.fps() as f64,
        }
    }

    /// The joint names, in message order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The stamp of `tick`: `offset_ns` plus the tick's time on the audio clock, to the
    /// nearest nanosecond.
    pub fn stamp(&self, tick: u64, offset_ns: i64) -> Time {
        let t = (tick as f64 * 1e9 / self.fps.max(1e-9)).round() as i64;
        Time::from_nanos(offset_ns.saturating_add(t))
    }

    /// The message of `tick` with commanded angles `angles_deg` (degrees, one per channel).
    pub fn message(&self, tick: u64, offset_ns: i64, angles_deg: &[f32]) -> JointState {
        JointState {
            header: Header {
                stamp: self.stamp(tick, offset_ns),
                frame_id: String::new(),
            },
            name: self.names.clone(),
            position: angles_deg
                .iter()
                .take(self.names.len())
                .map(|&a| (a as f64).to_radians())
                .collect(),
            velocity: Vec::new(),
            effort: Vec::new(),
        }
    }
}

/// Starts the DDS publisher on `topic` (default [`DEFAULT_TOPIC`]) in the domain
/// `ROS_DOMAIN_ID` names: a bad topic or domain, or a build without the `ros2` feature, is
/// an error before anything is sent.
pub fn start(topic: Option<&str>) -> Result<Publisher, Ros2Error> {
    let topic = topic.unwrap_or(DEFAULT_TOPIC);
    topic_name(topic)?;
    let domain = domain_id(std::env::var("ROS_DOMAIN_ID").ok().as_deref())?;
    Publisher::new(topic, domain)
}

/// The wall clock in nanoseconds since the Unix epoch (0 if the clock is before it): the
/// origin of live stamps.
pub fn unix_nanos() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX))
}

#[cfg(feature = "ros2")]
pub use dds::Publisher;

/// Stands in for the DDS publisher in a build without the `ros2` feature: it never starts.
#[cfg(not(feature = "ros2"))]
pub enum Publisher {}

#[cfg(not(feature = "ros2"))]
impl Publisher {
    /// Always [`Ros2Error::NoFeature`] in a build without the `ros2` feature.
    pub fn new(_topic: &str, _domain: u16) -> Result<Self, Ros2Error> {
        Err(Ros2Error::NoFeature)
    }

    /// The topic.
    pub fn topic(&self) -> &str {
        match *self {}
    }

    /// The domain.
    pub fn domain(&self) -> u16 {
        match *self {}
    }

    /// Messages published.
    pub fn sent(&self) -> usize {
        match *self {}
    }

    /// The origin of the stamps.
    pub fn origin_ns(&self) -> i64 {
        match *self {}
    }

    /// Never called.
    pub fn set_origin_ns(&mut self, _ns: i64) {
        match *self {}
    }

    /// Never called.
    pub fn publish(&mut self, _msg: JointState) -> Result<(), Ros2Error> {
        match *self {}
    }

    /// Never called.
    pub fn finish(&mut self) {
        match *self {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stamps_are_ticks_on_the_audio_clock() {
        let s = JointStream {
            names: vec!["a".into(), "b".into()],
            fps: 30.0,
        };
        assert_eq!(s.stamp(0, 0), Time::default());
        assert_eq!(s.stamp(30, 0), Time { sec: 1, nanosec: 0 });
        assert_eq!(s.stamp(1, 0).nanosec, 33_333_333);
        assert_eq!(s.stamp(2, 5_000_000_000).nanos(), 5_066_666_667);
        let m = s.message(3, 0, &[90.0, -180.0]);
        assert_eq!(m.name, ["a", "b"]);
        assert_eq!(m.position, [(90.0f64).to_radians(), -std::f64::consts::PI]);
        assert_eq!(m.header.stamp.nanos(), 100_000_000);
    }
}
