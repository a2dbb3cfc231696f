//! The DDS side (feature `ros2`): one participant in the `ROS_DOMAIN_ID` domain, a node
//! `/gesture_sim` and a `sensor_msgs/msg/JointState` publisher, through `ros2-client` on
//! RustDDS (pure Rust, no ROS installation). QoS: [`super::topic::QOS`], which matches both
//! reliable subscribers (`ros2 topic echo`, rclpy's default) and best-effort ones
//! (`robot_state_publisher`'s sensor-data profile); samples sent before a subscriber is
//! discovered are not kept for it (volatile), as with any ROS 2 publisher.

use std::time::Duration;

use ros2_client::{
    qos::{Durability, History, WhenFull},
    Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions, QosProfile,
};

use super::error::Ros2Error;
use super::msg::JointState;
use super::topic::{full_topic, topic_name};

/// A running JointState publisher.
pub struct Publisher {
    // Kept alive: dropping the node or the context stops the participant.
    _node: Node,
    _context: Context,
    publisher: ros2_client::Publisher<JointState>,
    topic: String,
    domain: u16,
    sent: usize,
    origin_ns: i64,
}

impl Publisher {
    /// Joins `domain` and starts publishing on `topic` (checked with [`topic_name`]).
    pub fn new(topic: &str, domain: u16) -> Result<Self, Ros2Error> {
        let (ns, base) = topic_name(topic)?;
        let start = |e: String| Ros2Error::Start(e);
        let context = Context::with_options(ContextOptions::new().domain_id(domain))
            .map_err(|e| start(format!("{e:?}")))?;
        let mut node = context
            .new_node(
                NodeName::new("/", "gesture_sim").map_err(|e| start(format!("{e:?}")))?,
                NodeOptions::new().enable_rosout(false),
            )
            .map_err(|e| start(format!("{e:?}")))?;
        let qos = QosProfile::publisher_default()
            .reliability_reliable(WhenFull::DEFAULT)
            .durability(Durability::Volatile)
            .history(History::KeepLast { depth: 100 });
        let name = Name::new(&ns, &base).map_err(|e| Ros2Error::Topic {
            topic: topic.to_string(),
            reason: format!("{e:?}"),
        })?;
        let t = node
            .create_topic(
                &name,
                MessageTypeName::new("sensor_msgs", "JointState"),
                &qos,
            )
            .map_err(|e| start(format!("{e:?}")))?;
        let publisher = node
            .create_publisher::<JointState>(&t, None)
            .map_err(|e| start(format!("{e:?}")))?;
        let full = full_topic(Some(topic))?;
        Ok(Self {
            _node: node,
            _context: context,
            publisher,
            topic: full,
            domain,
            sent: 0,
            origin_ns: 0,
        })
    }

    /// The topic's full name.
    pub fn topic(&self) -> &str {
        &self.topic
    }

    /// The DDS domain.
    pub fn domain(&self) -> u16 {
        self.domain
    }

    /// Messages published.
    pub fn sent(&self) -> usize {
        self.sent
    }

    /// The origin of the stamps (ns since the Unix epoch): when the audio clock started.
    pub fn origin_ns(&self) -> i64 {
        self.origin_ns
    }

    /// Sets the origin of the stamps.
    pub fn set_origin_ns(&mut self, ns: i64) {
        self.origin_ns = ns;
    }

    /// Publishes one message.
    pub fn publish(&mut self, msg: JointState) -> Result<(), Ros2Error> {
        self.publisher
            .publish(msg)
            .map_err(|e| Ros2Error::Publish(format!("{e:?}")))?;
        self.sent += 1;
        Ok(())
    }

    /// Stays half a second after the last message, so reliable resends to a subscriber that
    /// missed one can complete before the participant leaves.
    pub fn finish(&mut self) {
        std::thread::sleep(Duration::from_millis(500));
    }
}
