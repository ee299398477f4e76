//! A campaign as ROS 2 messages in an MCAP file (`--mcap-out`,
//! docs/USER-GUIDE.md "Robot software"): what Foxglove, rerun, `ros2 bag
//! play` and any ROS 2 node read. The topics are [`super::ros_out`]'s, every
//! message stamped with the campaign's clock (the time model's hours since
//! the first scan began): the knowledge map after every scan, every planning
//! round, every scan and station.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use cpsplan::mission::Step;
use cpsplan::OccupancyGrid;

use super::ros_out::{Outlet, RosOut};
use crate::report::{write_temp, TempFile};

pub use super::ros_out::clock_ns;

/// An MCAP file being written in memory: channels and schemas added on first use.
pub struct McapFile {
    writer: mcap::Writer<Cursor<Vec<u8>>>,
    channels: BTreeMap<String, u16>,
    schemas: BTreeMap<&'static str, u16>,
    sequence: u32,
}

/// A campaign's messages into an MCAP file (moved into place by
/// [`McapOut::finish`]).
pub type McapOut = RosOut<McapFile>;

impl Outlet for McapFile {
    fn send(
        &mut self,
        topic: &str,
        kind: &'static str,
        schema: fn() -> String,
        ns: u64,
        cdr: &[u8],
    ) -> Result<()> {
        let channel = match self.channels.get(topic) {
            Some(&id) => id,
            None => {
                let schema = match self.schemas.get(kind) {
                    Some(&id) => id,
                    None => {
                        let id = self
                            .writer
                            .add_schema(kind, "ros2msg", schema().as_bytes())?;
                        self.schemas.insert(kind, id);
                        id
                    }
                };
                let id = self
                    .writer
                    .add_channel(schema, topic, "cdr", &BTreeMap::new())?;
                self.channels.insert(topic.to_string(), id);
                id
            }
        };
        self.sequence += 1;
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: self.sequence,
            log_time: ns,
            publish_time: ns,
        };
        self.writer.write_to_known_channel(&header, cdr)?;
        Ok(())
    }
}

impl RosOut<McapFile> {
    /// A new file for a team of `children` children.
    pub fn new(children: usize) -> Result<Self> {
        let options = mcap::WriteOptions::new()
            .compression(None)
            .profile("ros2")
            .library("cpsplan");
        let writer = options
            .create(Cursor::new(Vec::new()))
            .context("cannot start the MCAP file")?;
        let file = McapFile {
            writer,
            channels: BTreeMap::new(),
            schemas: BTreeMap::new(),
            sequence: 0,
        };
        Ok(Self::with_outlet(file, children))
    }

    /// Finishes the file and writes it under a temporary name beside `path`,
    /// to be moved into place ([`TempFile::persist`]) once everything else is.
    pub fn finish(self, path: &Path) -> Result<TempFile> {
        let mut file = self.into_outlet();
        file.writer
            .finish()
            .context("cannot finish the MCAP file")?;
        let bytes = file.writer.into_inner().into_inner();
        write_temp(path, &bytes)
    }
}

/// A run's optional MCAP recording (`--mcap-out`), fed from the callbacks of
/// an episode or a campaign step: nothing without a path; otherwise the first
/// error is kept (later messages are skipped) and reported as `--mcap-out`.
pub struct McapRecording {
    out: Option<(PathBuf, McapOut)>,
    error: Option<anyhow::Error>,
}

impl McapRecording {
    /// A recording into `path` for a team of `children` children, or none.
    pub fn new(path: Option<&Path>, children: usize) -> Result<Self> {
        let out = match path {
            Some(p) => Some((p.to_path_buf(), McapOut::new(children)?)),
            None => None,
        };
        Ok(Self { out, error: None })
    }

    /// Applies `write` to the file, if there is one and nothing failed yet;
    /// an error is kept for [`Self::check`].
    pub fn with(&mut self, write: impl FnOnce(&mut McapOut) -> Result<()>) {
        if let (Some((_, m)), None) = (self.out.as_mut(), self.error.as_ref()) {
            self.error = write(m).err();
        }
    }

    /// A planning step's messages ([`McapOut::record`]).
    pub fn record(&mut self, step: &Step, knowledge: &OccupancyGrid) {
        self.with(|m| m.record(step, knowledge));
    }

    /// The first error so far, as `--mcap-out`.
    pub fn check(&mut self) -> Result<()> {
        match self.error.take() {
            Some(e) => Err(e.context("--mcap-out")),
            None => Ok(()),
        }
    }

    /// Finishes the file under a temporary name beside its path
    /// ([`McapOut::finish`]), after [`Self::check`]; `None` without a file.
    pub fn finish(mut self) -> Result<Option<McapFinished>> {
        self.check()?;
        let Some((path, m)) = self.out else {
            return Ok(None);
        };
        let tmp = m.finish(&path).context("--mcap-out")?;
        Ok(Some(McapFinished { path, tmp }))
    }
}

/// A finished recording under its temporary name.
pub struct McapFinished {
    path: PathBuf,
    tmp: TempFile,
}

impl McapFinished {
    /// Moves the file into place, once everything else of the run is.
    pub fn persist(self) -> Result<()> {
        self.tmp.persist(&self.path)
    }
}
