//! [`SrvType`]: one known ROS 2 service type, a pair of message types.

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

    /// Indices of the request and response types in the registry.
    pub(crate) fn halves(&self) -> (usize, usize) {
        (self.request, self.response)
    }
}
