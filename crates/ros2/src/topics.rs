//! Opening the graph's topics under ROS 2's names, and writing to them: shared by the
//! graph's own topics ([`crate::graph`]) and the robot descriptions
//! ([`crate::description`]).

use gantry_ros::{Direction, EndpointId, EndpointSpec, NetworkError, RosNetwork, RosQos};

/// Opens `topic` of `ros_type`, with ROS 2's DDS names (the codec's mangling).
pub(crate) fn open(
    net: &dyn RosNetwork,
    dir: Direction,
    topic: &str,
    ros_type: &str,
    qos: RosQos,
) -> Result<EndpointId, NetworkError> {
    let dds_topic = gantry_protocol::ros::topic_name(topic).map_err(|e| NetworkError(e.to_string()))?;
    let ty = gantry_protocol::ros::message_type(ros_type).map_err(|e| NetworkError(e.to_string()))?;
    net.open(&EndpointSpec {
        direction: dir,
        dds_topic,
        dds_type: ty.dds_type_name(),
        qos,
    })
}

/// Sends a message the codecs here encoded (with the encapsulation header; the network
/// wants the body after it). A failure is the network's to report: the graph goes on.
pub(crate) fn send(net: &dyn RosNetwork, id: EndpointId, message: &[u8]) {
    let body = message.get(4..).map(<[u8]>::to_vec).unwrap_or_default();
    if let Err(e) = net.write(id, body) {
        tracing::debug!("ROS 2 graph: {e}");
    }
}

/// ROS's topic name rules allow letters, digits and `_` in each token, which must not
/// start with a digit: other characters of a frame id become `_`.
pub fn topic_token(frame: &str) -> String {
    let mut out = String::with_capacity(frame.len() + 1);
    for (i, part) in frame.split('/').filter(|p| !p.is_empty()).enumerate() {
        if i > 0 {
            out.push('/');
        }
        if part.starts_with(|c: char| c.is_ascii_digit()) {
            out.push('_');
        }
        out.extend(
            part.chars()
                .map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_tokens_follow_ros_name_rules() {
        assert_eq!(topic_token("bubbleRob/visionSensor"), "bubbleRob/visionSensor");
        assert_eq!(topic_token("wheel[1]/cam-2"), "wheel_1_/cam_2");
        assert_eq!(topic_token("3d/cam"), "_3d/cam");
    }
}
