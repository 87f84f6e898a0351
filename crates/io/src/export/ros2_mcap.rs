//! One `trajectory_msgs/msg/JointTrajectory` message in an MCAP file, the ROS 2 bag format:
//! schema encoding `ros2msg` (the message definitions as `ros2 interface show` prints them
//! concatenated), message encoding `cdr` (little-endian CDR behind its 4-byte encapsulation
//! header, as ROS 2's middleware sends it).

use std::collections::BTreeMap;
use std::io::Cursor;

use serde::Serialize;

use crate::joint_trajectory::JointTrajectoryPoint;

/// The message type, as ROS 2 names it.
pub const JOINT_TRAJECTORY_TYPE: &str = "trajectory_msgs/msg/JointTrajectory";

/// The `ros2msg` schema of [`JOINT_TRAJECTORY_TYPE`] with the types it uses.
const SCHEMA: &str = "\
std_msgs/Header header
string[] joint_names
JointTrajectoryPoint[] points

================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id

================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec

================================================================================
MSG: trajectory_msgs/JointTrajectoryPoint
float64[] positions
float64[] velocities
float64[] accelerations
float64[] effort
builtin_interfaces/Duration time_from_start

================================================================================
MSG: builtin_interfaces/Duration
int32 sec
uint32 nanosec
";

/// The topic of the tool's switching, beside the trajectory.
pub const TOOL_OUTPUT_TOPIC: &str = "/emg/tool_output";
/// The message type of the tool's switching: `data` true switches the tool on.
pub const TOOL_OUTPUT_TYPE: &str = "std_msgs/msg/Bool";
/// The `ros2msg` schema of [`TOOL_OUTPUT_TYPE`].
const TOOL_OUTPUT_SCHEMA: &str = "bool data\n";

/// CDR encapsulation header: CDR, little-endian, no options.
const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// `builtin_interfaces/Time` and `builtin_interfaces/Duration` (the same layout).
#[derive(Serialize)]
struct Stamp {
    sec: i32,
    nanosec: u32,
}

/// `std_msgs/Header`.
#[derive(Serialize)]
struct Header<'a> {
    stamp: Stamp,
    frame_id: &'a str,
}

/// `trajectory_msgs/JointTrajectoryPoint`.
#[derive(Serialize)]
struct Point<'a> {
    positions: &'a [f64],
    velocities: &'a [f64],
    accelerations: &'a [f64],
    effort: &'a [f64],
    time_from_start: Stamp,
}

/// `trajectory_msgs/JointTrajectory`.
#[derive(Serialize)]
struct Message<'a> {
    header: Header<'a>,
    joint_names: &'a [String],
    points: Vec<Point<'a>>,
}

/// What the message holds besides the points.
pub struct Ros2Message<'a> {
    /// The joints' names as the driver takes them.
    pub joint_names: &'a [String],
    /// `header.frame_id`.
    pub frame_id: &'a str,
    /// The channel's topic.
    pub topic: &'a str,
    /// Notes written as the file's `emg_export` metadata record (the source, the driver, the
    /// frames, the thinning).
    pub notes: BTreeMap<String, String>,
    /// The tool's switches, written on [`TOOL_OUTPUT_TOPIC`] at their times.
    pub tool: Option<&'a [super::tool::ToolSwitch]>,
}

/// The CDR bytes of the message with `points` (the header's stamp zero: "start now" to
/// `joint_trajectory_controller`).
fn cdr(message: &Ros2Message<'_>, points: &[&JointTrajectoryPoint]) -> Result<Vec<u8>, String> {
    let body = Message {
        header: Header {
            stamp: Stamp { sec: 0, nanosec: 0 },
            frame_id: message.frame_id,
        },
        joint_names: message.joint_names,
        points: points
            .iter()
            .map(|p| Point {
                positions: &p.positions,
                velocities: &p.velocities,
                accelerations: &p.accelerations,
                effort: &[],
                time_from_start: Stamp {
                    sec: p.time_from_start.sec,
                    nanosec: p.time_from_start.nanosec,
                },
            })
            .collect(),
    };
    let encoded = cdr_encoding::to_vec::<_, byteorder::LittleEndian>(&body)
        .map_err(|e| format!("CDR encoding failed: {e}"))?;
    let mut bytes = CDR_LE_HEADER.to_vec();
    bytes.extend(encoded);
    Ok(bytes)
}

/// The MCAP file holding one message on `message.topic` with the points `kept` of `points`,
/// logged at time 0, and the tool's switches on [`TOOL_OUTPUT_TOPIC`] at their times.
pub fn mcap_bytes(
    points: &[JointTrajectoryPoint],
    kept: &[usize],
    message: &Ros2Message<'_>,
) -> Result<Vec<u8>, String> {
    let points: Vec<&JointTrajectoryPoint> = kept.iter().map(|&k| &points[k]).collect();
    let data = cdr(message, &points)?;
    let fail = |e: mcap::McapError| format!("MCAP writing failed: {e}");
    let options = mcap::WriteOptions::new()
        .compression(None)
        .profile("ros2")
        .library(concat!("emg-io ", env!("CARGO_PKG_VERSION")));
    let mut writer = options.create(Cursor::new(Vec::new())).map_err(fail)?;
    let schema = writer
        .add_schema(JOINT_TRAJECTORY_TYPE, "ros2msg", SCHEMA.as_bytes())
        .map_err(fail)?;
    let channel = writer
        .add_channel(schema, message.topic, "cdr", &BTreeMap::new())
        .map_err(fail)?;
    writer
        .write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: channel,
                sequence: 0,
                log_time: 0,
                publish_time: 0,
            },
            &data,
        )
        .map_err(fail)?;
    if let Some(switches) = message.tool {
        let schema = writer
            .add_schema(TOOL_OUTPUT_TYPE, "ros2msg", TOOL_OUTPUT_SCHEMA.as_bytes())
            .map_err(fail)?;
        let channel = writer
            .add_channel(schema, TOOL_OUTPUT_TOPIC, "cdr", &BTreeMap::new())
            .map_err(fail)?;
        for (sequence, switch) in (1..).zip(switches) {
            // `std_msgs/msg/Bool`: one byte behind the encapsulation header.
            let mut data = CDR_LE_HEADER.to_vec();
            data.push(u8::from(switch.on));
            let time_ns = (switch.time_s * 1e9).round() as u64;
            writer
                .write_to_known_channel(
                    &mcap::records::MessageHeader {
                        channel_id: channel,
                        sequence,
                        log_time: time_ns,
                        publish_time: time_ns,
                    },
                    &data,
                )
                .map_err(fail)?;
        }
    }
    writer
        .write_metadata(&mcap::records::Metadata {
            name: "emg_export".to_string(),
            metadata: message.notes.clone(),
        })
        .map_err(fail)?;
    writer.finish().map_err(fail)?;
    Ok(writer.into_inner().into_inner())
}
