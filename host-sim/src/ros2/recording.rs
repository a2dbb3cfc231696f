//! The joint states as an MCAP file (profile `ros2`): what `ros2 bag`, Foxglove and the
//! `rosbags` library open as a ROS 2 recording.
//!
//! One schema (`sensor_msgs/msg/JointState`, encoding `ros2msg`, the definition text of
//! [`msg::JOINT_STATE_DEFINITION`]), one channel (the topic, message encoding `cdr`), one
//! message per tick in CDR ([`msg::JointState::to_cdr`]). Log time, publish time and the
//! header stamp are the tick's time on the audio clock (0 = the first sample), so the same
//! run gives the same bytes. Uncompressed (the crate's compressors would bring C libraries
//! into the default build), chunked and indexed with the crate's defaults, so players can seek.
//! Built in memory; the caller writes it atomically.

use std::collections::BTreeMap;
use std::io::Cursor;

use super::msg::{self, JOINT_STATE_DEFINITION, JOINT_STATE_TYPE};
use super::JointStream;

/// The MCAP bytes of `angles` (one row of commanded angles in degrees per tick) on `topic`.
pub fn mcap_bytes(
    stream: &JointStream,
    topic: &str,
    angles: &[Vec<f32>],
) -> Result<Vec<u8>, String> {
    let e = |e: mcap::McapError| e.to_string();
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .library(concat!("gesture-sim ", env!("CARGO_PKG_VERSION")))
        .compression(None)
        .create(Cursor::new(Vec::new()))
        .map_err(e)?;
    let schema = w
        .add_schema(
            JOINT_STATE_TYPE,
            "ros2msg",
            JOINT_STATE_DEFINITION.as_bytes(),
        )
        .map_err(e)?;
    let channel = w
        .add_channel(schema, topic, "cdr", &BTreeMap::new())
        .map_err(e)?;
    for (tick, row) in angles.iter().enumerate() {
        let m: msg::JointState = stream.message(tick as u64, 0, row);
        let t = m.header.stamp.nanos().max(0) as u64;
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: channel,
                sequence: tick as u32,
                log_time: t,
                publish_time: t,
            },
            &m.to_cdr(),
        )
        .map_err(e)?;
    }
    w.finish().map_err(e)?;
    Ok(w.into_inner().into_inner())
}
