//! Why ROS 2 output could not start or go on, and the exit status each reason gives.

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
