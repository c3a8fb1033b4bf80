//! [`SrvType`]: one known ROS 2 service type, a pair of message types.

use super::msg_type::MsgType;
use super::registry::nested;

/// A ROS 2 service type known to gantry: its request and response message types.
#[derive(Debug)]
pub struct SrvType {
    /// `pkg/srv/Type`.
    name: String,
    /// Indices of `pkg/srv/Type_Request` and `pkg/srv/Type_Response` in the registry.
    request: usize,
    response: usize,
}

impl SrvType {
    pub(crate) fn new(name: String, request: usize, response: usize) -> SrvType {
        SrvType {
            name,
            request,
            response,
        }
    }

    /// The canonical name, `std_srvs/srv/SetBool`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The request's message type, `std_srvs/srv/SetBool_Request`.
    pub fn request(&self) -> &MsgType {
        nested(self.request)
    }

    /// The response's message type, `std_srvs/srv/SetBool_Response`.
    pub fn response(&self) -> &MsgType {
        nested(self.response)
    }

    /// The DDS type name of requests: `std_srvs::srv::dds_::SetBool_Request_`.
    pub fn dds_request_type_name(&self) -> String {
        self.request().dds_type_name()
    }

    /// The DDS type name of responses: `std_srvs::srv::dds_::SetBool_Response_`.
    pub fn dds_response_type_name(&self) -> String {
        self.response().dds_type_name()
    }
}
