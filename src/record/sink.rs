//! Where a recording goes: an `.rrd` file (the default), a live viewer, or both.
//!
//! All destinations are rerun sinks of one stream (rerun's `MultiSink`), so a run can write its
//! file and stream to a viewer at the same time, with the same data in both.

use std::path::{Path, PathBuf};

use rerun::sink::{FileSink, GrpcSink, LogSink};

use super::{BoxError, RecordError};

/// A live viewer to stream the recording to, besides (or instead of) the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LiveViewer {
    /// Start a Rerun viewer (`rerun` on `PATH`, version 0.36.3) and stream to it. A viewer
    /// already listening on rerun's default port (9876) is reused.
    Spawn,
    /// Stream to a running viewer at this gRPC proxy URL, e.g.
    /// `rerun+http://127.0.0.1:9876/proxy` (what `rerun` prints when it starts).
    Connect(String),
}

/// Where one recording goes. At least one of the two must be set.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RecordTarget {
    /// The `.rrd` file to write (created, or truncated, when recording starts).
    pub file: Option<PathBuf>,
    /// A live viewer to stream to.
    pub live: Option<LiveViewer>,
}

impl RecordTarget {
    /// Just a file.
    pub fn file(path: &Path) -> RecordTarget {
        RecordTarget {
            file: Some(path.to_path_buf()),
            live: None,
        }
    }

    /// A human-readable description for messages: `file x.rrd`, `viewer at URL`, or both.
    pub fn describe(&self) -> String {
        let live = self.live.as_ref().map(|l| match l {
            LiveViewer::Spawn => "a spawned viewer".to_owned(),
            LiveViewer::Connect(url) => format!("viewer at {url}"),
        });
        match (&self.file, live) {
            (Some(f), None) => format!("file {}", f.display()),
            (Some(f), Some(l)) => format!("file {} and {l}", f.display()),
            (None, Some(l)) => l,
            (None, None) => "nowhere".to_owned(),
        }
    }
}

/// Opens every sink of `target`: the file first (so an unwritable path fails before a viewer
/// starts), then the viewer.
pub(super) fn open_sinks(target: &RecordTarget) -> Result<Vec<Box<dyn LogSink>>, RecordError> {
    let err = |source: BoxError| RecordError::Create {
        target: target.describe(),
        source,
    };
    let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
    if let Some(path) = &target.file {
        sinks.push(Box::new(FileSink::new(path).map_err(|e| err(Box::new(e)))?));
    }
    match &target.live {
        None => {}
        Some(LiveViewer::Connect(url)) => sinks.push(Box::new(grpc_sink(url).map_err(err)?)),
        Some(LiveViewer::Spawn) => {
            if find_on_path("rerun").is_none() {
                return Err(err(
                    "--spawn needs the Rerun viewer 0.36.3 as `rerun` on PATH; install it with \
                     `pip install rerun-sdk==0.36.3` or `cargo install rerun-cli --version 0.36.3`, \
                     or start a viewer yourself and use --connect"
                        .into(),
                ));
            }
            let info =
                rerun::spawn(&rerun::SpawnOptions::default()).map_err(|e| err(Box::new(e)))?;
            let url = format!("rerun+http://127.0.0.1:{}/proxy", info.port);
            sinks.push(Box::new(grpc_sink(&url).map_err(err)?));
        }
    }
    if sinks.is_empty() {
        return Err(err("no file and no viewer to record to".into()));
    }
    Ok(sinks)
}

/// The batching of a recording without a live viewer: rerun's default thresholds (a chunk
/// per entity once its rows reach 2 MiB) without the 200 ms wall-clock tick, so that the rows
/// of many frames share a chunk (and its schema) however long a frame takes to simulate.
/// Everything still pending is written when the recording is flushed or closed.
pub(super) fn file_only_batching() -> rerun::log::ChunkBatcherConfig {
    rerun::log::ChunkBatcherConfig {
        flush_tick: std::time::Duration::MAX,
        ..rerun::log::ChunkBatcherConfig::DEFAULT
    }
}

/// A gRPC sink for a proxy URL; anything else (a catalog URL, garbage) is an error.
fn grpc_sink(url: &str) -> Result<GrpcSink, BoxError> {
    use rerun::external::re_uri::RedapUri;
    match url.parse::<RedapUri>() {
        Ok(RedapUri::Proxy(uri)) => Ok(GrpcSink::new(uri)),
        Ok(_) => Err(format!(
            "{url} is not a viewer's proxy URL (expected e.g. rerun+http://127.0.0.1:9876/proxy)"
        )
        .into()),
        Err(e) => Err(format!(
            "{url} is not a viewer URL ({e}); expected e.g. rerun+http://127.0.0.1:9876/proxy"
        )
        .into()),
    }
}

/// The first executable file named `name` in a directory of `PATH`.
fn find_on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
}
