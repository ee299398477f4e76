//! A campaign as ROS 2 messages in an MCAP file (`--mcap-out`,
//! docs/USER-GUIDE.md "Robot software"): what Foxglove, rerun, `ros2 bag
//! play` and any ROS 2 node read. The topics are [`super::ros_out`]'s, every
//! message stamped with the campaign's clock (the time model's hours since
//! the first scan began): the knowledge map after every scan, every planning
//! round, every scan and station.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;

use anyhow::{Context, Result};

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
