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
//! - [`recording`]: the MCAP file.
//! - [`urdf`]: the character as a URDF, its joints named as the messages name them.

pub mod msg;
pub mod recording;
pub mod urdf;

#[cfg(feature = "ros2")]
mod dds;

use gesture_runtime::blob::Blob;

use msg::{Header, JointState, Time};

/// The default topic (what `robot_state_publisher` subscribes to).
pub const DEFAULT_TOPIC: &str = "/joint_states";

/// Why ROS 2 output could not start or go on.
#[derive(Debug, thiserror::Error)]
pub enum Ros2Error {
    /// A build without the `ros2` feature was asked for `--ros2`.
    #[error(
        "--ros2 needs the `ros2` feature: cargo run --release -p host-sim --features ros2 -- ..."
    )]
    NoFeature,
    /// The topic name is not a ROS 2 topic name.
    #[error("--ros2-topic {topic:?}: {reason}")]
    Topic {
        /// What was given.
        topic: String,
        /// What is wrong.
        reason: String,
    },
    /// `ROS_DOMAIN_ID` is set to something that is not a domain.
    #[error("ROS_DOMAIN_ID={value:?}: not a ROS 2 domain (an integer from 0 to 232; 0-101 are safe on Linux)")]
    Domain {
        /// The variable's value.
        value: String,
    },
    /// The DDS participant or publisher could not start.
    #[error("--ros2: starting DDS: {0}")]
    Start(String),
    /// Publishing failed.
    #[error("--ros2: publishing: {0}")]
    Publish(String),
    /// The MCAP file could not be made or written.
    #[error("{}: {reason}", path.display())]
    Mcap {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
    /// The blob's skeleton and channels do not make a URDF.
    #[error("URDF: {0}")]
    Urdf(String),
}

impl Ros2Error {
    /// Exit status: 2 for bad input, 1 for failures of the network or the file system.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::NoFeature | Self::Topic { .. } | Self::Domain { .. } | Self::Urdf(_) => 2,
            Self::Start(_) | Self::Publish(_) | Self::Mcap { .. } => 1,
        }
    }
}

/// A checked topic name: `(namespace, base name)`, e.g. `("/", "joint_states")` or
/// `("/robot", "joint_states")`. A relative name is taken from the root namespace (the node
/// lives there). Tokens are ASCII letters, digits and `_`, not starting with a digit, with
/// no `__`; `~` and `{}` substitutions are not supported.
pub fn topic_name(topic: &str) -> Result<(String, String), Ros2Error> {
    let bad = |reason: &str| Ros2Error::Topic {
        topic: topic.to_string(),
        reason: reason.to_string(),
    };
    let rel = topic.strip_prefix('/').unwrap_or(topic);
    if rel.is_empty() {
        return Err(bad("empty (give a name such as /joint_states)"));
    }
    if rel.ends_with('/') {
        return Err(bad("ends with '/'"));
    }
    let tokens: Vec<&str> = rel.split('/').collect();
    for t in &tokens {
        if t.is_empty() {
            return Err(bad("has an empty part ('//')"));
        }
        if let Some(c) = t
            .chars()
            .find(|c| !(c.is_ascii_alphanumeric() || *c == '_'))
        {
            return Err(bad(&format!(
                "{c:?} is not allowed (letters, digits, '_' and '/' only)"
            )));
        }
        if t.starts_with(|c: char| c.is_ascii_digit()) {
            return Err(bad("a part starts with a digit"));
        }
        if t.contains("__") {
            return Err(bad("has '__' (reserved)"));
        }
    }
    let (ns, base) = tokens.split_at(tokens.len() - 1);
    Ok((format!("/{}", ns.join("/")), base[0].to_string()))
}

/// The DDS domain from `ROS_DOMAIN_ID` (`value`; unset or empty: 0), as ROS 2 reads it.
pub fn domain_id(value: Option<&str>) -> Result<u16, Ros2Error> {
    let v = value.map(str::trim).unwrap_or("");
    if v.is_empty() {
        return Ok(0);
    }
    match v.parse::<u16>() {
        Ok(d) if d <= 232 => Ok(d),
        _ => Err(Ros2Error::Domain {
            value: v.to_string(),
        }),
    }
}

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

/// The full name of a checked topic (`/joint_states`, `/robot/joint_states`).
pub fn full_topic(topic: Option<&str>) -> Result<String, Ros2Error> {
    let (ns, base) = topic_name(topic.unwrap_or(DEFAULT_TOPIC))?;
    Ok(if ns == "/" {
        format!("/{base}")
    } else {
        format!("{ns}/{base}")
    })
}

/// The QoS of the publisher, as the docs state it.
pub const QOS: &str = "reliable, volatile, keep last 100";

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
    fn topic_names_are_checked_and_split() {
        let ok = |t: &str| topic_name(t).unwrap();
        assert_eq!(ok("/joint_states"), ("/".into(), "joint_states".into()));
        assert_eq!(ok("joint_states"), ("/".into(), "joint_states".into()));
        assert_eq!(ok("/robot/arm/js2"), ("/robot/arm".into(), "js2".into()));
        for bad in ["", "/", "/a/", "//a", "/a b", "/1a", "/a__b", "~/a", "/a.b"] {
            assert!(topic_name(bad).is_err(), "{bad:?} accepted");
        }
    }

    #[test]
    fn domain_ids_are_read_as_ros_does() {
        assert_eq!(domain_id(None).unwrap(), 0);
        assert_eq!(domain_id(Some("")).unwrap(), 0);
        assert_eq!(domain_id(Some(" 42 ")).unwrap(), 42);
        assert_eq!(domain_id(Some("232")).unwrap(), 232);
        for bad in ["233", "-1", "x", "1.5"] {
            let e = domain_id(Some(bad)).unwrap_err();
            assert_eq!(e.exit_code(), 2);
        }
    }

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
