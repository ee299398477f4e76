//! `cpsplan ros`: a campaign as a live ROS 2 node (docs/USER-GUIDE.md
//! "Robot software"), in pure Rust DDS: no ROS installation is needed, and
//! any ROS 2 node on the same domain talks to it.
//!
//! It subscribes to a scan (`/cpsplan/input/scan`, `sensor_msgs/PointCloud2`
//! in the scanner's frame) and the total station's readings since the scan
//! before (`/cpsplan/input/readings`, `std_msgs/String` holding the readings
//! CSV, header included). Once both have arrived it adds them to the campaign
//! directory exactly as `cpsplan campaign add` does, and publishes the
//! outcome: `/cpsplan/next` (`std_msgs/String`, the `next.json` text),
//! `/cpsplan/status` (`std_msgs/String`, the summary or why the scan was
//! refused) and the topics of `--mcap-out` (knowledge map, the new scan's
//! registered points and station, the paths, the plan, `tf`), stamped with
//! the wall clock. Every publisher is reliable and transient-local with a
//! depth of one: a node that joins later gets the latest of each.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anyhow::{anyhow, Context as _, Result};
use clap::Args;
use cpsplan::model::ModelPoint;
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher,
    QosProfile, Subscription,
};
use serde::ser::SerializeTuple;
use serde::{Serialize, Serializer};

use super::add::{prepare, ScanInput};
use super::store::CampaignFile;
use crate::errors::one_line;
use crate::formats::cloud::encode_ply;
use crate::formats::readings::parse_readings;
use crate::formats::ros2_in::PointCloud2;
use crate::formats::ros_out::{Outlet, RosOut};

/// The topic scans arrive on.
pub const SCAN_TOPIC: &str = "/cpsplan/input/scan";
/// The topic readings arrive on.
pub const READINGS_TOPIC: &str = "/cpsplan/input/readings";
/// The topic the next plan (`next.json`) goes out on.
pub const NEXT_TOPIC: &str = "/cpsplan/next";
/// The topic each scan's outcome goes out on.
pub const STATUS_TOPIC: &str = "/cpsplan/status";

/// How long the node keeps publishing after its last scan (`--scans`), so
/// that reliable subscribers get the last messages.
const LINGER: Duration = Duration::from_secs(3);
/// How often the subscriptions are looked at.
const POLL: Duration = Duration::from_millis(50);

/// Options of `cpsplan ros`.
#[derive(Debug, Args)]
pub struct RosArgs {
    /// The campaign's directory (made by `cpsplan campaign init`).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// The ROS domain id [default: ROS_DOMAIN_ID, else 0].
    #[arg(long, value_name = "ID")]
    pub domain: Option<u16>,
    /// Stop after this many scans (added or refused) [default: run until
    /// interrupted].
    #[arg(long, value_name = "N")]
    pub scans: Option<usize>,
    /// Stop with an error when nothing arrives for this many seconds.
    #[arg(long, value_name = "SECONDS")]
    pub idle_timeout: Option<f64>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// A message already in CDR: its bytes after the encapsulation header,
/// serialized as they are (a tuple of bytes adds neither length nor padding).
struct RawCdr(Vec<u8>);

impl Serialize for RawCdr {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(self.0.len())?;
        for b in &self.0 {
            t.serialize_element(b)?;
        }
        t.end()
    }
}

/// The QoS of everything the node publishes and subscribes to.
fn qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::DEFAULT)
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 1 })
}

/// A topic's name as ros2-client takes it.
fn topic_name(topic: &str) -> Result<Name> {
    let (ns, base) = topic.rsplit_once('/').unwrap_or(("", topic));
    let ns = if ns.is_empty() { "/" } else { ns };
    Name::new(ns, base).map_err(|e| anyhow!("topic {topic}: {e}"))
}

/// A message type's name (`package/msg/Name`) as ros2-client takes it.
fn type_name(kind: &str) -> MessageTypeName {
    let (package, name) = kind.split_once("/msg/").unwrap_or(("", kind));
    MessageTypeName::new(package, name)
}

/// A publisher of `kind` messages on `topic` for `node`.
fn publisher<M: Serialize>(node: &mut Node, topic: &str, kind: &str) -> Result<Publisher<M>> {
    let t = node
        .create_topic(&topic_name(topic)?, type_name(kind), &qos())
        .map_err(|e| anyhow!("topic {topic}: {e}"))?;
    node.create_publisher(&t, None)
        .map_err(|e| anyhow!("publisher of {topic}: {e}"))
}

/// The node's publishers, one a topic, made on first use.
struct LiveOutlet {
    node: Node,
    publishers: HashMap<String, Publisher<RawCdr>>,
    text: HashMap<&'static str, Publisher<String>>,
}

impl LiveOutlet {
    /// Publishes `text` as a `std_msgs/String` on `topic`.
    fn say(&mut self, topic: &'static str, text: String) -> Result<()> {
        if !self.text.contains_key(topic) {
            let p = publisher(&mut self.node, topic, "std_msgs/msg/String")?;
            self.text.insert(topic, p);
        }
        let p = self.text.get(topic).context("a text publisher")?;
        p.publish(text)
            .map_err(|e| anyhow!("cannot publish on {topic}: {e}"))
    }

    fn subscribe<D: 'static>(&mut self, topic: &str, kind: &str) -> Result<Subscription<D>> {
        let t = self
            .node
            .create_topic(&topic_name(topic)?, type_name(kind), &qos())
            .map_err(|e| anyhow!("topic {topic}: {e}"))?;
        self.node
            .create_subscription(&t, None)
            .map_err(|e| anyhow!("subscription to {topic}: {e}"))
    }
}

impl Outlet for LiveOutlet {
    fn send(
        &mut self,
        topic: &str,
        kind: &'static str,
        _schema: fn() -> String,
        _ns: u64,
        cdr: &[u8],
    ) -> Result<()> {
        if !self.publishers.contains_key(topic) {
            let p = publisher(&mut self.node, topic, kind)?;
            self.publishers.insert(topic.to_string(), p);
        }
        let p = self.publishers.get(topic).context("a publisher")?;
        let body = cdr.get(4..).unwrap_or_default().to_vec();
        p.publish(RawCdr(body))
            .map_err(|e| anyhow!("cannot publish on {topic}: {e}"))
    }
}

/// Nanoseconds since the Unix epoch.
fn now_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
}

/// The ROS domain of `args`: `--domain`, else `ROS_DOMAIN_ID`, else 0.
fn domain_of(args: &RosArgs) -> Result<u16> {
    if let Some(d) = args.domain {
        return Ok(d);
    }
    match std::env::var("ROS_DOMAIN_ID") {
        Ok(v) if !v.trim().is_empty() => v
            .trim()
            .parse()
            .map_err(|_| anyhow!("ROS_DOMAIN_ID={v} is not a domain id (0 to 232)")),
        _ => Ok(0),
    }
}

/// `cpsplan ros`.
pub fn run(args: &RosArgs) -> Result<()> {
    let dir = &args.dir;
    let state = CampaignFile::load(dir)?;
    let domain = domain_of(args)?;
    let context = Context::with_options(ContextOptions::new().domain_id(domain))
        .map_err(|e| anyhow!("cannot join ROS domain {domain}: {e}"))?;
    let node = context
        .new_node(
            NodeName::new("/", "cpsplan").map_err(|e| anyhow!("{e}"))?,
            NodeOptions::new(),
        )
        .map_err(|e| anyhow!("cannot start the node: {e}"))?;
    let mut outlet = LiveOutlet {
        node,
        publishers: HashMap::new(),
        text: HashMap::new(),
    };
    let scans: Subscription<PointCloud2> =
        outlet.subscribe(SCAN_TOPIC, "sensor_msgs/msg/PointCloud2")?;
    let readings: Subscription<String> = outlet.subscribe(READINGS_TOPIC, "std_msgs/msg/String")?;
    let mut out = RosOut::with_outlet(outlet, state.config.children.count);
    if let Ok(next) = std::fs::read_to_string(dir.join("next.json")) {
        out.outlet_mut().say(NEXT_TOPIC, next)?;
    }
    if !args.quiet {
        println!(
            "cpsplan ros: campaign {} ({} scans so far) on ROS domain {domain}; \
             waiting for {SCAN_TOPIC} and {READINGS_TOPIC}",
            dir.display(),
            state.scans.len()
        );
    }

    let mut scan: Option<PointCloud2> = None;
    let mut text: Option<String> = None;
    let mut handled = 0;
    let mut last_input = Instant::now();
    loop {
        while let Some((m, _)) = scans.take().map_err(|e| anyhow!("{SCAN_TOPIC}: {e}"))? {
            scan = Some(m);
            last_input = Instant::now();
        }
        while let Some((m, _)) = readings
            .take()
            .map_err(|e| anyhow!("{READINGS_TOPIC}: {e}"))?
        {
            text = Some(m);
            last_input = Instant::now();
        }
        match (scan.take(), text.take()) {
            (Some(cloud), Some(csv)) => {
                let status = match add(dir, &cloud, csv, &mut out) {
                    Ok(summary) => summary,
                    Err(e) => {
                        let line = one_line(&e);
                        eprintln!("error: {line}");
                        format!("refused: {line}")
                    }
                };
                if !args.quiet {
                    println!("{status}");
                }
                out.outlet_mut().say(STATUS_TOPIC, status)?;
                handled += 1;
            }
            // Wait for the other half.
            (s, t) => (scan, text) = (s, t),
        }
        if args.scans.is_some_and(|n| handled >= n) {
            std::thread::sleep(LINGER);
            return Ok(());
        }
        if let Some(limit) = args.idle_timeout {
            if last_input.elapsed().as_secs_f64() > limit {
                anyhow::bail!("nothing arrived on {SCAN_TOPIC} and {READINGS_TOPIC} for {limit} s");
            }
        }
        std::thread::sleep(POLL);
    }
}

/// Adds a scan and its readings to the campaign in `dir` and publishes the
/// outcome; returns the summary.
fn add(
    dir: &Path,
    cloud: &PointCloud2,
    csv: String,
    out: &mut RosOut<LiveOutlet>,
) -> Result<String> {
    let state = CampaignFile::load(dir)?;
    let config = &state.config;
    let n = state.scans.len() + 1;
    let points = cloud.points(config.limits.max_cloud_points)?;
    let readings = parse_readings(&csv, Path::new(READINGS_TOPIC))?;
    let model: Vec<ModelPoint> = points
        .iter()
        .map(|&position| ModelPoint {
            position,
            scan: u32::try_from(n).unwrap_or(u32::MAX),
        })
        .collect();
    let input = ScanInput {
        cloud: points,
        cloud_file: (encode_ply(&model)?, "ply".into()),
        readings,
        readings_csv: csv.into_bytes(),
        readings_from: PathBuf::from(READINGS_TOPIC),
    };
    out.forget_paths();
    let mut prepared = prepare(dir, input, |step, _| out.drive(step))?;
    prepared.commit(dir)?;

    let ns = now_ns();
    if let Some(k) = &prepared.run.episode.knowledge {
        out.map(ns, k)?;
    }
    out.scan(ns, &prepared.registered()?)?;
    prepared.send_station(out, ns, &prepared.station)?;
    if let Some(step) = prepared.run.episode.steps.last() {
        out.plan_state(ns, step)?;
    }
    let next = serde_json::to_string_pretty(&prepared.next)?;
    out.outlet_mut().say(NEXT_TOPIC, next + "\n")?;
    Ok(prepared.summary())
}
