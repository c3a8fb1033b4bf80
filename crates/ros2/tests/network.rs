//! gantry's DDS network end to end on this host: two participants in a domain of their
//! own, one publishing and one subscribing, as two ROS 2 nodes would (Cyclone DDS, an
//! independent implementation, is the peer in tests/python/test_ros2.py). Samples
//! arrive as written, an inbox keeps at most its QoS depth and counts what it dropped,
//! and a network that cannot start says why on every call.

use std::time::{Duration, Instant};

use gantry_ros::{Direction, EndpointSpec, RosNetwork, RosQos};
use gantry_ros2::{DdsNetwork, DiscoveryRange, RosConfig};

fn config(domain: u16) -> RosConfig {
    RosConfig {
        domain_id: domain,
        range: DiscoveryRange::Localhost,
    }
}

/// A domain unlikely to be in use by another test run on this host.
fn domain(salt: u16) -> u16 {
    let pid = u16::try_from(std::process::id() % 60).unwrap_or(0);
    150 + (pid + salt) % 80
}

fn spec(direction: Direction, depth: u32) -> EndpointSpec {
    EndpointSpec {
        direction,
        dds_topic: "rt/gantry_test".to_owned(),
        dds_type: "std_msgs::msg::dds_::UInt32_".to_owned(),
        qos: RosQos {
            depth,
            ..RosQos::default()
        },
    }
}

#[test]
fn samples_cross_from_one_participant_to_another() {
    let d = domain(0);
    let talker = DdsNetwork::new(config(d));
    let listener = DdsNetwork::new(config(d));
    let sub = listener.open(&spec(Direction::Subscribe, 100)).expect("subscription");
    let publ = talker.open(&spec(Direction::Publish, 100)).expect("publisher");
    // Discovery takes a moment: write until something arrives, then a known run.
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut got = Vec::new();
    while got.is_empty() {
        assert!(Instant::now() < deadline, "nothing arrived: {:?}", talker.stats());
        talker.write(publ, 0_u32.to_le_bytes().to_vec()).expect("write");
        std::thread::sleep(Duration::from_millis(20));
        got = listener.take(sub, 1000);
    }
    for i in 1..=20_u32 {
        talker.write(publ, i.to_le_bytes().to_vec()).expect("write");
    }
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut values: Vec<u32> = Vec::new();
    while !values.contains(&20) {
        assert!(Instant::now() < deadline, "only {values:?} arrived");
        std::thread::sleep(Duration::from_millis(10));
        values.extend(listener.take(sub, 1000).into_iter().map(|s| {
            assert!(s.little_endian);
            u32::from_le_bytes(s.body[..4].try_into().expect("4 bytes"))
        }));
    }
    let run: Vec<u32> = values.into_iter().filter(|&v| v > 0).collect();
    // Discovery's view, for simROS2.waitForService: each side sees the other.
    let deadline = Instant::now() + Duration::from_secs(10);
    while talker.matched(publ) == 0 || listener.matched(sub) == 0 {
        assert!(Instant::now() < deadline, "no match seen");
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(run, (1..=20).collect::<Vec<_>>(), "reliable and in order");
    let stats = listener.stats();
    assert_eq!(stats.len(), 1);
    assert!(stats[0].messages >= 21);
    talker.close(publ);
    assert!(talker.stats().is_empty());
    assert!(
        talker.write(publ, vec![0; 4]).is_err(),
        "a closed publisher refuses writes"
    );
}

#[test]
fn an_inbox_keeps_its_depth_and_counts_the_rest() {
    let d = domain(7);
    let talker = DdsNetwork::new(config(d));
    let listener = DdsNetwork::new(config(d));
    let sub = listener.open(&spec(Direction::Subscribe, 3)).expect("subscription");
    let publ = talker.open(&spec(Direction::Publish, 100)).expect("publisher");
    let deadline = Instant::now() + Duration::from_secs(30);
    // Nobody takes: after discovery, 50 writes leave the newest 3 in the inbox.
    while listener.stats()[0].messages == 0 {
        assert!(Instant::now() < deadline, "nothing arrived");
        talker.write(publ, 0_u32.to_le_bytes().to_vec()).expect("write");
        std::thread::sleep(Duration::from_millis(20));
    }
    for i in 1..=50_u32 {
        talker.write(publ, i.to_le_bytes().to_vec()).expect("write");
    }
    // Wait until the last write has arrived and nothing more comes.
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut last = 0;
    loop {
        assert!(Instant::now() < deadline, "{:?}", listener.stats());
        std::thread::sleep(Duration::from_millis(300));
        let now = listener.stats()[0].messages;
        if now == last {
            break;
        }
        last = now;
    }
    let stats = listener.stats()[0].clone();
    let kept = listener.take(sub, 1000);
    assert_eq!(kept.len(), 3, "the QoS depth: {stats:?}");
    assert_eq!(
        stats.dropped,
        stats.messages - 3,
        "every other arrival is counted as dropped"
    );
    assert_eq!(
        u32::from_le_bytes(kept[2].body[..4].try_into().expect("4 bytes")),
        50,
        "the newest are kept"
    );
}

#[test]
fn a_network_that_cannot_start_says_why() {
    let n = DdsNetwork::unavailable("ROS_DOMAIN_ID=\"x\" is not a domain id".to_owned());
    let e = n.open(&spec(Direction::Publish, 1)).unwrap_err();
    assert!(e.to_string().contains("ROS_DOMAIN_ID"), "{e}");
    assert!(n.start_now().is_err());
    assert!(n.take(1, 10).is_empty());
}
