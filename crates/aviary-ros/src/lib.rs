//! ROS 2 for Aviary (docs/ROS2.md): the fleet's telemetry and the trace as ROS 2 messages
//! in CDR ([`msgs`]), and a recorded trace as a rosbag2 bag in MCAP ([`bag`]) that
//! `ros2 bag`, rosbags and Foxglove open.
//!
//! Invariant: no IO but the bag's files, which [`bag::write`] is given the folder of.

pub mod bag;
pub mod hash;
pub mod msgs;
pub mod topics;
