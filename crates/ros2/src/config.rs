//! Where gantry joins a ROS 2 graph: the domain and the discovery range, from ROS's own
//! environment variables so that gantry meets the nodes a user already runs.

use std::net::{IpAddr, Ipv4Addr};

/// How far discovery reaches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiscoveryRange {
    /// This host only (the loopback interface): gantry's default, like its servers
    /// that bind to 127.0.0.1.
    Localhost,
    /// Every interface: other machines on the subnet see gantry's topics.
    Subnet,
}

/// The domain and range (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RosConfig {
    /// `ROS_DOMAIN_ID`, 0 to 232.
    pub domain_id: u16,
    /// `ROS_AUTOMATIC_DISCOVERY_RANGE` (Jazzy) or `ROS_LOCALHOST_ONLY` (Humble).
    pub range: DiscoveryRange,
}

/// Why the environment does not describe a graph gantry can join.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ConfigError {
    /// `ROS_DOMAIN_ID` is not an integer from 0 to 232.
    #[error("ROS_DOMAIN_ID={0:?} is not a domain id (an integer from 0 to 232)")]
    Domain(String),
    /// `ROS_AUTOMATIC_DISCOVERY_RANGE` has a value gantry does not serve.
    #[error("ROS_AUTOMATIC_DISCOVERY_RANGE={0:?} is not served (LOCALHOST or SUBNET; OFF would hide every topic)")]
    Range(String),
}

/// The largest domain id ROS 2 allows (the RTPS port formula overflows beyond it).
pub const MAX_DOMAIN_ID: u16 = 232;

impl RosConfig {
    /// Reads the configuration through `var` (the process environment in
    /// [`RosConfig::from_env`]; a map in tests).
    ///
    /// `ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET` (or `SYSTEM_DEFAULT`), or
    /// `ROS_LOCALHOST_ONLY=0` when the first is unset, opens discovery to the subnet;
    /// otherwise gantry stays on this host.
    ///
    /// # Errors
    /// A domain id or range that is not valid.
    pub fn from_vars(var: impl Fn(&str) -> Option<String>) -> Result<Self, ConfigError> {
        let domain_id = match var("ROS_DOMAIN_ID").map(|s| s.trim().to_owned()) {
            None => 0,
            Some(s) if s.is_empty() => 0,
            Some(s) => match s.parse::<u16>() {
                Ok(d) if d <= MAX_DOMAIN_ID => d,
                _ => return Err(ConfigError::Domain(s)),
            },
        };
        let range = match var("ROS_AUTOMATIC_DISCOVERY_RANGE").map(|s| s.trim().to_ascii_uppercase()) {
            Some(r) if r == "LOCALHOST" => DiscoveryRange::Localhost,
            Some(r) if r == "SUBNET" || r == "SYSTEM_DEFAULT" => DiscoveryRange::Subnet,
            Some(r) if !r.is_empty() => return Err(ConfigError::Range(r)),
            _ => match var("ROS_LOCALHOST_ONLY").map(|s| s.trim().to_owned()) {
                Some(s) if s == "0" => DiscoveryRange::Subnet,
                _ => DiscoveryRange::Localhost,
            },
        };
        Ok(Self { domain_id, range })
    }

    /// [`RosConfig::from_vars`] on the process environment.
    ///
    /// # Errors
    /// As [`RosConfig::from_vars`].
    pub fn from_env() -> Result<Self, ConfigError> {
        Self::from_vars(|k| std::env::var(k).ok())
    }

    /// The interfaces RustDDS may use: `None` for all.
    pub(crate) fn interfaces(&self) -> Option<Vec<IpAddr>> {
        match self.range {
            DiscoveryRange::Localhost => Some(vec![IpAddr::V4(Ipv4Addr::LOCALHOST)]),
            DiscoveryRange::Subnet => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn config(vars: &[(&str, &str)]) -> Result<RosConfig, ConfigError> {
        let map: HashMap<String, String> = vars.iter().map(|(k, v)| ((*k).to_owned(), (*v).to_owned())).collect();
        RosConfig::from_vars(|k| map.get(k).cloned())
    }

    #[test]
    fn defaults_are_domain_zero_on_this_host() {
        assert_eq!(
            config(&[]),
            Ok(RosConfig {
                domain_id: 0,
                range: DiscoveryRange::Localhost
            })
        );
    }

    #[test]
    fn ros_variables_choose_the_domain_and_the_range() {
        let c = config(&[("ROS_DOMAIN_ID", "42"), ("ROS_AUTOMATIC_DISCOVERY_RANGE", "subnet")]).unwrap();
        assert_eq!((c.domain_id, c.range), (42, DiscoveryRange::Subnet));
        let c = config(&[("ROS_LOCALHOST_ONLY", "0")]).unwrap();
        assert_eq!(c.range, DiscoveryRange::Subnet);
        let c = config(&[("ROS_LOCALHOST_ONLY", "1")]).unwrap();
        assert_eq!(c.range, DiscoveryRange::Localhost);
        // The newer variable wins over the older one.
        let c = config(&[
            ("ROS_LOCALHOST_ONLY", "0"),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST"),
        ])
        .unwrap();
        assert_eq!(c.range, DiscoveryRange::Localhost);
    }

    #[test]
    fn bad_values_are_refused_by_name() {
        let e = config(&[("ROS_DOMAIN_ID", "300")]).unwrap_err();
        assert!(e.to_string().contains("ROS_DOMAIN_ID=\"300\""), "{e}");
        let e = config(&[("ROS_DOMAIN_ID", "x")]).unwrap_err();
        assert!(matches!(e, ConfigError::Domain(_)));
        let e = config(&[("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")]).unwrap_err();
        assert!(e.to_string().contains("OFF"), "{e}");
    }
}
