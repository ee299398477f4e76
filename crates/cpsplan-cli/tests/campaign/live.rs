//! `cpsplan ros`: the live node fed as a robot's software would feed it, by
//! another ROS 2 participant with its own message definitions (serde over
//! CDR, independent of the node's own encoder): the scan it adds gives the
//! same `next.json` as `campaign add` with the same files, the map it
//! publishes is the one it wrote, and bad readings are refused over the
//! status topic with the directory unchanged.

use std::io::Read;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use cpsplan_cli::formats::cloud::{read_cloud, CloudReadOptions};
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher,
    QosProfile, Subscription,
};
use serde::{de::DeserializeOwned, Deserialize, Serialize};

use super::{add, edited, field_data, init, pgm, scan_files, snapshot};

/// The domain of the test's node (one of its own, away from the default 0).
const DOMAIN: u16 = 77;
/// The domain of the loopback check.
const PROBE_DOMAIN: u16 = 78;
/// How long anything may take before the test gives up.
const PATIENCE: Duration = Duration::from_secs(180);

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct Time {
    sec: i32,
    nanosec: u32,
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct Header {
    stamp: Time,
    frame_id: String,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct PointField {
    name: String,
    offset: u32,
    datatype: u8,
    count: u32,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct PointCloud2 {
    header: Header,
    height: u32,
    width: u32,
    fields: Vec<PointField>,
    is_bigendian: bool,
    point_step: u32,
    row_step: u32,
    data: Vec<u8>,
    is_dense: bool,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct Quaternion {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct Pose {
    position: Vector3,
    orientation: Quaternion,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct MapMetaData {
    map_load_time: Time,
    resolution: f32,
    width: u32,
    height: u32,
    origin: Pose,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct OccupancyGrid {
    header: Header,
    info: MapMetaData,
    data: Vec<i8>,
}

fn qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::DEFAULT)
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 4 })
}

/// A topic's name and type as ros2-client takes them.
fn names(name: &str, package: &str, kind: &str) -> (Name, MessageTypeName) {
    let (ns, base) = name.rsplit_once('/').unwrap();
    let ns = if ns.is_empty() { "/" } else { ns };
    (
        Name::new(ns, base).unwrap(),
        MessageTypeName::new(package, kind),
    )
}

fn publisher<M: Serialize>(node: &mut Node, name: &str, package: &str, kind: &str) -> Publisher<M> {
    let (name, kind) = names(name, package, kind);
    let t = node.create_topic(&name, kind, &qos()).unwrap();
    node.create_publisher(&t, None).unwrap()
}

fn subscription<M: DeserializeOwned + 'static>(
    node: &mut Node,
    name: &str,
    package: &str,
    kind: &str,
) -> Subscription<M> {
    let (name, kind) = names(name, package, kind);
    let t = node.create_topic(&name, kind, &qos()).unwrap();
    node.create_subscription(&t, None).unwrap()
}

fn node(domain: u16, name: &str) -> (Context, Node) {
    let context = Context::with_options(ContextOptions::new().domain_id(domain)).unwrap();
    let node = context
        .new_node(NodeName::new("/", name).unwrap(), NodeOptions::new())
        .unwrap();
    (context, node)
}

/// Whether two DDS participants on this machine find each other: a message
/// published on a loopback topic arrives within a minute.
fn dds_works() -> bool {
    let (_a, mut a) = node(PROBE_DOMAIN, "probe_a");
    let (_b, mut b) = node(PROBE_DOMAIN, "probe_b");
    let p: Publisher<String> = publisher(&mut a, "/probe", "std_msgs", "String");
    let s: Subscription<String> = subscription(&mut b, "/probe", "std_msgs", "String");
    let t = Instant::now();
    while t.elapsed() < Duration::from_secs(60) {
        p.publish("ping".into()).unwrap();
        if let Ok(Some(_)) = s.take() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    false
}

/// A scan file as a `PointCloud2` of float64 `x, y, z`.
fn cloud_message(path: &Path) -> PointCloud2 {
    let cloud = read_cloud(path, &CloudReadOptions::default(), &mut |_, _| {}).unwrap();
    let mut data = Vec::with_capacity(cloud.points.len() * 24);
    for p in &cloud.points {
        for v in p {
            data.extend_from_slice(&v.to_le_bytes());
        }
    }
    let field = |name: &str, offset| PointField {
        name: name.into(),
        offset,
        datatype: 8,
        count: 1,
    };
    PointCloud2 {
        header: Header {
            stamp: Time::default(),
            frame_id: "scanner".into(),
        },
        height: 1,
        width: cloud.points.len() as u32,
        fields: vec![field("x", 0), field("y", 8), field("z", 16)],
        is_bigendian: false,
        point_step: 24,
        row_step: 24 * cloud.points.len() as u32,
        data,
        is_dense: true,
    }
}

/// Takes messages from `s` until `done` says so, or fails after
/// [`PATIENCE`] (checking that `node` still runs).
fn wait_for<M>(s: &Subscription<M>, node: &mut Child, mut done: impl FnMut(M) -> bool)
where
    M: DeserializeOwned + 'static,
{
    let t = Instant::now();
    loop {
        while let Ok(Some((m, _))) = s.take() {
            if done(m) {
                return;
            }
        }
        if let Ok(Some(status)) = node.try_wait() {
            panic!("cpsplan ros ended early: {status}");
        }
        assert!(t.elapsed() < PATIENCE, "no answer from cpsplan ros");
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn the_live_node_adds_a_scan_as_campaign_add_does() {
    if !dds_works() {
        eprintln!("SKIP: two DDS participants on this machine do not find each other (no multicast on loopback?)");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (_, field) = field_data(tmp.path(), "site", Some(2));
    let (by_file, live) = (tmp.path().join("by-file"), tmp.path().join("live"));
    init(&field, &by_file);
    init(&field, &live);
    add(&by_file, &field, 1);

    let mut cpsplan = Command::new(env!("CARGO_BIN_EXE_cpsplan"))
        .args(["ros", "-q", "--domain", &DOMAIN.to_string(), "--scans", "2"])
        .args(["--idle-timeout", &PATIENCE.as_secs().to_string()])
        .arg(&live)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (_context, mut robot) = node(DOMAIN, "robot");
    let scan: Publisher<PointCloud2> = publisher(
        &mut robot,
        "/cpsplan/input/scan",
        "sensor_msgs",
        "PointCloud2",
    );
    let readings: Publisher<String> =
        publisher(&mut robot, "/cpsplan/input/readings", "std_msgs", "String");
    let next: Subscription<String> =
        subscription(&mut robot, "/cpsplan/next", "std_msgs", "String");
    let status: Subscription<String> =
        subscription(&mut robot, "/cpsplan/status", "std_msgs", "String");
    let map: Subscription<OccupancyGrid> =
        subscription(&mut robot, "/map", "nav_msgs", "OccupancyGrid");

    // Scan 1 with its readings.
    let (cloud, csv) = scan_files(&field, 1);
    scan.publish(cloud_message(&cloud)).unwrap();
    readings
        .publish(std::fs::read_to_string(&csv).unwrap())
        .unwrap();
    let mut said = String::new();
    wait_for(&status, &mut cpsplan, |s| {
        said = s;
        true
    });
    assert!(said.starts_with("scan 1: station S0000"), "{said}");
    let mut plan = String::new();
    wait_for(&next, &mut cpsplan, |s| {
        plan = s;
        true
    });
    let expected = std::fs::read_to_string(by_file.join("next.json")).unwrap();
    assert_eq!(plan, expected, "the plan published is campaign add's");
    assert_eq!(
        std::fs::read_to_string(live.join("next.json")).unwrap(),
        expected,
        "the plan written is campaign add's"
    );
    let mut grid = None;
    wait_for(&map, &mut cpsplan, |m| {
        grid = Some(m);
        true
    });
    let grid = grid.unwrap();
    let (w, h, pixels) = pgm(&live.join("knowledge.pgm"));
    assert_eq!(
        (grid.info.width as usize, grid.info.height as usize),
        (w, h)
    );
    let yaml = std::fs::read_to_string(live.join("knowledge.yaml")).unwrap();
    let origin = yaml
        .lines()
        .find_map(|l| l.strip_prefix("origin:"))
        .unwrap()
        .trim()
        .trim_matches(['[', ']']);
    let origin: Vec<f64> = origin
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    let resolution: f32 = yaml
        .lines()
        .find_map(|l| l.strip_prefix("resolution:"))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert_eq!(grid.info.resolution, resolution);
    assert_eq!(
        [grid.info.origin.position.x, grid.info.origin.position.y],
        [origin[0], origin[1]]
    );
    // Row 0 of the message is the map's bottom row, the PGM's last.
    for (k, &v) in grid.data.iter().enumerate() {
        let (x, y) = (k % w, k / w);
        let pixel = pixels[(h - 1 - y) * w + x];
        let expected = match pixel {
            254 => 0,
            0 => 100,
            _ => -1,
        };
        assert_eq!(v, expected, "cell ({x}, {y})");
    }

    // Scan 2 with a reading to an unknown point: refused, nothing changed.
    let before = snapshot(&live);
    let bad = edited(&field, 2, &tmp.path().join("bad.csv"), |lines| {
        let mut cols: Vec<String> = lines[1].split(',').map(str::to_string).collect();
        cols[1] = "X77".into();
        lines[1] = cols.join(",");
    });
    let (cloud, _) = scan_files(&field, 2);
    scan.publish(cloud_message(&cloud)).unwrap();
    readings
        .publish(std::fs::read_to_string(&bad).unwrap())
        .unwrap();
    wait_for(&status, &mut cpsplan, |s| {
        said = s;
        true
    });
    assert!(
        said.starts_with("refused:") && said.contains("unknown point `X77`"),
        "{said}"
    );
    let t = Instant::now();
    let end = loop {
        if let Some(s) = cpsplan.try_wait().unwrap() {
            break s;
        }
        assert!(
            t.elapsed() < PATIENCE,
            "cpsplan ros did not stop after --scans 2"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(end.success(), "{end}");
    let mut errors = String::new();
    cpsplan
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut errors)
        .unwrap();
    assert_eq!(errors.lines().count(), 1, "{errors}");
    assert!(errors.starts_with("error: "), "{errors}");
    assert!(errors.contains("unknown point `X77`"), "{errors}");
    assert!(
        before == snapshot(&live),
        "the refused scan changed the campaign"
    );
}

/// The node refuses what `campaign add` refuses before it joins the network:
/// no campaign directory, a directory of another version; and it stops with
/// one line when nothing arrives within `--idle-timeout`.
#[test]
fn the_live_node_refuses_a_bad_directory_and_gives_up_when_idle() {
    use super::common::refused;
    let tmp = tempfile::tempdir().unwrap();
    let none = tmp.path().join("none");
    refused(&["ros", none.to_str().unwrap()], "campaign.json");
    let (_, field) = field_data(tmp.path(), "site", Some(1));
    let camp = tmp.path().join("campaign");
    init(&field, &camp);
    let state = camp.join("campaign.json");
    let text = std::fs::read_to_string(&state).unwrap();
    std::fs::write(&state, text.replace("\"version\": 1", "\"version\": 2")).unwrap();
    refused(&["ros", camp.to_str().unwrap()], "version 2");
    std::fs::write(&state, text).unwrap();
    refused(
        &[
            "ros",
            "-q",
            "--domain",
            &(DOMAIN + 2).to_string(),
            "--idle-timeout",
            "0.5",
            camp.to_str().unwrap(),
        ],
        "nothing arrived on /cpsplan/input/scan",
    );
    assert!(!camp.join("next.json").exists(), "nothing was added");
}
