//! The `.rrd` file itself, written so that the same calls give the same bytes.
//!
//! Rerun's `RecordingStream` makes every file different: its row and chunk ids are TUIDs from the
//! clock plus randomness, its recording id is random, it adds the wall-clock timeline `log_time`
//! and a start time, and its batcher cuts chunks on a timer, so the chunking (and the size)
//! depends on the machine's speed. This writer does the stream's work itself, with none of that:
//! - the ids of rows and chunks count up from 1 (a TUID of time 0 and increment n), in the order
//!   of the calls, so they still order the rows as logged;
//! - the store ids are given by the caller ([`super::rerun_file`]: derived from the file's name);
//! - the only timeline is the one set with [`RrdWriter::set_duration_secs`] (`sim_time`);
//! - rows are gathered per entity, static or not, and archetype, and a chunk is cut when it holds
//!   [`CHUNK_MAX_ROWS`] rows or [`CHUNK_MAX_BYTES`] bytes, and at the end in the order the
//!   entities first appeared: by count, never by time;
//! - the footer (Rerun's index of the chunks) lists the stores in a fixed order (the blueprint,
//!   then the recording), where Rerun's own encoder follows a `HashMap`'s random order, and its
//!   schema's columns sorted.
//!
//! The chunks are built on the caller's thread and encoded (Arrow IPC, LZ4) and written by one
//! writer thread, in the order they were built: the thread changes when bytes are written,
//! never which.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use rerun::external::re_log_encoding::{
    self, CrateVersion, Encodable, EncodingOptions, MessageHeader, MessageKind, RawRrdManifest,
    RrdFooter, RrdManifestBuilder, StreamFooter, StreamHeader, ToTransport,
};
use rerun::external::re_log_types::{ArrowMsg, SetStoreInfo, StoreId, StoreInfo};
use rerun::log::{Chunk, ChunkId, LogMsg, RowId};
use rerun::{AsComponents, EntityPath, SerializedComponentBatch, StoreKind, TimeCell, TimePoint};

use super::RecordingError;

/// A chunk is cut when it holds this many rows…
pub(super) const CHUNK_MAX_ROWS: usize = 256;
/// …or this many bytes of (uncompressed) component data.
pub(super) const CHUNK_MAX_BYTES: usize = 256 << 10;
/// The blueprint's store.
pub(super) const BLUEPRINT_STORE: usize = 0;
/// The recording's store.
pub(super) const RECORDING_STORE: usize = 1;
/// Chunks waiting for the writer thread (the caller waits when it is behind).
const CHUNKS_IN_FLIGHT: usize = 64;

/// Rows waiting to become a chunk: one entity, static or not, one archetype.
struct Pending {
    store: usize,
    entity_path: EntityPath,
    is_static: bool,
    rows: Vec<(RowId, TimePoint, Vec<SerializedComponentBatch>)>,
    bytes: usize,
}

/// One store of the file (the blueprint or the recording) and its part of the footer.
struct Store {
    id: StoreId,
    manifest: RrdManifestBuilder,
    has_chunks: bool,
}

/// What the writer thread is sent.
enum Job {
    /// A chunk (its ids set) of store `.0`.
    Chunk(usize, Chunk),
    /// A message that is not data.
    Msg(LogMsg),
}

/// The file and its footer: owned by the writer thread once the stream header and the store
/// infos are written.
struct FileSide {
    path: PathBuf,
    out: BufWriter<File>,
    /// Bytes written so far.
    offset: u64,
    options: EncodingOptions,
    stores: Vec<Store>,
}

/// Writes an `.rrd` file with deterministic ids, chunks and footer.
pub(super) struct RrdWriter {
    store_ids: Vec<StoreId>,
    /// To the writer thread; `None` once finished.
    jobs: Option<SyncSender<Job>>,
    writer: Option<JoinHandle<Result<(), RecordingError>>>,
    /// The last id handed out (rows and chunks share the sequence).
    last_id: u64,
    /// The current time of the data logged with [`Self::log`].
    timepoint: TimePoint,
    pending: Vec<Pending>,
    /// Index in `pending` by (store, entity, static, archetype).
    pending_index: HashMap<(usize, String, bool, String), usize>,
}

/// A write error on `path`.
fn io_error(path: &Path, source: std::io::Error) -> RecordingError {
    RecordingError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// An encoding error of the Rerun libraries.
fn encode_error(call: &'static str, err: impl std::fmt::Display) -> RecordingError {
    RecordingError::InvalidInput {
        call,
        reason: err.to_string(),
    }
}

impl FileSide {
    fn write_bytes(&mut self, bytes: &[u8]) -> Result<(), RecordingError> {
        self.out
            .write_all(bytes)
            .map_err(|e| io_error(&self.path, e))?;
        self.offset += bytes.len() as u64;
        Ok(())
    }

    /// Writes one message; returns its byte span in the file (without its header) and its
    /// uncompressed size, which the footer's index of chunks holds.
    fn write_msg(&mut self, msg: &LogMsg) -> Result<(u64, u64, u64), RecordingError> {
        let transport = msg
            .to_transport(self.options.compression)
            .map_err(|e| encode_error("rrd message", e))?;
        let mut bytes = Vec::new();
        transport
            .to_rrd_bytes(&mut bytes)
            .map_err(|e| encode_error("rrd message", e))?;
        let header_bytes = MessageHeader::ENCODED_SIZE_BYTES as u64;
        let start = self.offset + header_bytes;
        let len = (bytes.len() as u64).saturating_sub(header_bytes);
        self.write_bytes(&bytes)?;
        Ok((start, len, transport.byte_size_uncompressed()))
    }

    /// Writes `chunk` (its ids already set) into store `store` and indexes it in the footer.
    fn write_chunk(&mut self, store: usize, chunk: &Chunk) -> Result<(), RecordingError> {
        let Some(store_id) = self.stores.get(store).map(|s| s.id.clone()) else {
            return Err(encode_error("rrd chunk", format!("no store {store}")));
        };
        let batch = chunk
            .to_chunk_batch()
            .map_err(|e| encode_error("rrd chunk", e))?;
        let msg = LogMsg::ArrowMsg(
            store_id,
            ArrowMsg {
                chunk_id: chunk.id().as_tuid(),
                batch: batch.clone().into(),
                on_release: None,
            },
        );
        let (start, len, uncompressed) = self.write_msg(&msg)?;
        if let Some(s) = self.stores.get_mut(store) {
            s.manifest
                .append(
                    &batch,
                    re_span::Span::from_start_len(start, len),
                    uncompressed,
                )
                .map_err(|e| encode_error("rrd footer", e))?;
            s.has_chunks = true;
        }
        Ok(())
    }

    /// The writer thread: writes the jobs in order until the channel closes, then the footer.
    fn run(mut self, jobs: Receiver<Job>) -> Result<(), RecordingError> {
        for job in jobs {
            match job {
                Job::Chunk(store, chunk) => self.write_chunk(store, &chunk)?,
                Job::Msg(msg) => {
                    self.write_msg(&msg)?;
                }
            }
        }
        self.finish()
    }

    /// Writes the footer (the stores in their order) and flushes the file.
    fn finish(mut self) -> Result<(), RecordingError> {
        let stores = std::mem::take(&mut self.stores);
        let mut footer: Option<<RrdFooter as ToTransport>::Output> = None;
        for store in stores.into_iter().filter(|s| s.has_chunks) {
            let mut manifest: RawRrdManifest = store
                .manifest
                .build(store.id.clone())
                .map_err(|e| encode_error("rrd footer", e))?;
            // The schema's columns come out of a `HashMap` in a random order: sorted, as Rerun
            // already sorts them for the schema's hash.
            let mut fields = manifest.sorbet_schema.fields().to_vec();
            fields.sort();
            manifest.sorbet_schema = rerun::external::arrow::datatypes::Schema::new_with_metadata(
                fields,
                manifest.sorbet_schema.metadata().clone(),
            );
            // One store per `RrdFooter` (its map's order is random), joined in our order.
            let one = RrdFooter {
                manifests: HashMap::from([(store.id, manifest)]),
            }
            .to_transport(())
            .map_err(|e| encode_error("rrd footer", e))?;
            match &mut footer {
                Some(f) => f.manifests.extend(one.manifests),
                None => footer = Some(one),
            }
        }
        if let Some(footer) = footer {
            let mut footer_bytes = Vec::new();
            footer
                .to_rrd_bytes(&mut footer_bytes)
                .map_err(|e| encode_error("rrd footer", e))?;
            let mut header = Vec::new();
            MessageHeader {
                kind: MessageKind::End,
                len: footer_bytes.len() as u64,
            }
            .to_rrd_bytes(&mut header)
            .map_err(|e| encode_error("rrd footer", e))?;
            self.write_bytes(&header)?;
            let footer_offset = self.offset;
            self.write_bytes(&footer_bytes)?;
            let mut stream_footer = Vec::new();
            StreamFooter::from_rrd_footer_bytes(footer_offset, &footer_bytes)
                .to_rrd_bytes(&mut stream_footer)
                .map_err(|e| encode_error("rrd footer", e))?;
            self.write_bytes(&stream_footer)?;
        }
        let path = self.path.clone();
        let file = self
            .out
            .into_inner()
            .map_err(|e| io_error(&path, e.into_error()))?;
        file.sync_all().map_err(|e| io_error(&path, e))
    }
}

impl RrdWriter {
    /// Creates `path`, writes the stream header and the store infos of the blueprint (if any:
    /// [`BLUEPRINT_STORE`]) and the recording ([`RECORDING_STORE`]) and starts the writer thread.
    pub(super) fn create(
        path: &Path,
        blueprint: Option<StoreInfo>,
        recording: StoreInfo,
    ) -> Result<Self, RecordingError> {
        let file = File::create(path).map_err(|e| io_error(path, e))?;
        let options = EncodingOptions::PROTOBUF_COMPRESSED;
        let mut file_side = FileSide {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(1 << 20, file),
            offset: 0,
            options,
            stores: Vec::new(),
        };
        let mut header = Vec::new();
        StreamHeader {
            fourcc: re_log_encoding::RRD_FOURCC,
            version: CrateVersion::LOCAL.to_bytes(),
            options,
        }
        .to_rrd_bytes(&mut header)
        .map_err(|e| encode_error("rrd header", e))?;
        file_side.write_bytes(&header)?;
        let mut writer = Self {
            store_ids: Vec::new(),
            jobs: None,
            writer: None,
            last_id: 0,
            timepoint: TimePoint::default(),
            pending: Vec::new(),
            pending_index: HashMap::new(),
        };
        // Without a blueprint, its store is never announced (and gets no rows).
        let blueprint_id = blueprint.as_ref().map_or_else(
            || {
                StoreId::new(
                    StoreKind::Blueprint,
                    recording.application_id().clone(),
                    recording.recording_id().clone(),
                )
            },
            |b| b.store_id.clone(),
        );
        for (id, info) in [
            (blueprint_id, blueprint),
            (recording.store_id.clone(), Some(recording)),
        ] {
            if let Some(info) = info {
                let row_id = writer.next_row_id();
                file_side.write_msg(&LogMsg::SetStoreInfo(SetStoreInfo {
                    row_id: *row_id,
                    info,
                }))?;
            }
            writer.store_ids.push(id.clone());
            file_side.stores.push(Store {
                id,
                manifest: RrdManifestBuilder::default(),
                has_chunks: false,
            });
        }
        let (jobs, received) = sync_channel(CHUNKS_IN_FLIGHT);
        let handle = std::thread::Builder::new()
            .name("rrd_writer".into())
            .spawn(move || file_side.run(received))
            .map_err(|e| io_error(path, e))?;
        writer.jobs = Some(jobs);
        writer.writer = Some(handle);
        Ok(writer)
    }

    /// The next id: a TUID of time 0 and increment `last_id + 1`.
    fn next_id(&mut self) -> u128 {
        self.last_id += 1;
        u128::from(self.last_id)
    }

    fn next_row_id(&mut self) -> RowId {
        RowId::from_u128(self.next_id())
    }

    /// Hands `job` to the writer thread; if it has stopped, its error.
    fn send(&mut self, job: Job) -> Result<(), RecordingError> {
        let sent = match &self.jobs {
            Some(jobs) => jobs.send(job).is_ok(),
            None => false,
        };
        if sent {
            Ok(())
        } else {
            // The thread stopped on an error: report it.
            self.join()?;
            Err(encode_error("rrd writer", "the writer thread has stopped"))
        }
    }

    /// Closes the channel and waits for the writer thread (which writes the footer).
    fn join(&mut self) -> Result<(), RecordingError> {
        self.jobs = None;
        match self.writer.take() {
            Some(handle) => handle
                .join()
                .map_err(|_| encode_error("rrd writer", "the writer thread panicked"))?,
            None => Ok(()),
        }
    }

    /// Sets the time of the data logged from now on.
    pub(super) fn set_timepoint(&mut self, timepoint: TimePoint) {
        self.timepoint = timepoint;
    }

    /// Sets the time of the data logged from now on: `secs` on the duration timeline
    /// `timeline`, the only timeline of the file.
    pub(super) fn set_duration_secs(&mut self, timeline: &'static str, secs: f64) {
        // As the SDK's `set_duration_secs`: a time it cannot hold leaves the time unchanged.
        let Ok(duration) = std::time::Duration::try_from_secs_f64(secs) else {
            return;
        };
        let mut timepoint = TimePoint::default();
        timepoint.insert_cell(timeline, TimeCell::from(duration));
        self.timepoint = timepoint;
    }

    /// Logs `value` at `path` in the recording at the current time.
    pub(super) fn log<AS: ?Sized + AsComponents>(
        &mut self,
        path: impl Into<EntityPath>,
        value: &AS,
    ) -> Result<(), RecordingError> {
        self.log_to(
            RECORDING_STORE,
            path.into(),
            false,
            value.as_serialized_batches(),
        )
    }

    /// Logs `value` at `path` in the recording as static data.
    pub(super) fn log_static<AS: ?Sized + AsComponents>(
        &mut self,
        path: impl Into<EntityPath>,
        value: &AS,
    ) -> Result<(), RecordingError> {
        self.log_to(
            RECORDING_STORE,
            path.into(),
            true,
            value.as_serialized_batches(),
        )
    }

    /// Adds a row to store `store`: static, or at the current time.
    pub(super) fn log_to(
        &mut self,
        store: usize,
        entity_path: EntityPath,
        is_static: bool,
        batches: Vec<SerializedComponentBatch>,
    ) -> Result<(), RecordingError> {
        if batches.is_empty() {
            return Ok(());
        }
        let archetype = batches
            .iter()
            .find_map(|b| b.descriptor.archetype.map(|a| a.to_string()))
            .unwrap_or_default();
        let key = (store, entity_path.to_string(), is_static, archetype);
        let index = match self.pending_index.get(&key) {
            Some(&i) => i,
            None => {
                self.pending.push(Pending {
                    store,
                    entity_path,
                    is_static,
                    rows: Vec::new(),
                    bytes: 0,
                });
                self.pending_index.insert(key, self.pending.len() - 1);
                self.pending.len() - 1
            }
        };
        let row_id = self.next_row_id();
        let timepoint = if is_static {
            TimePoint::default()
        } else {
            self.timepoint.clone()
        };
        let bytes: usize = batches
            .iter()
            .map(|b| rerun::external::arrow::array::Array::get_array_memory_size(&*b.array))
            .sum();
        let full = {
            let Some(p) = self.pending.get_mut(index) else {
                return Ok(());
            };
            p.rows.push((row_id, timepoint, batches));
            p.bytes += bytes;
            p.rows.len() >= CHUNK_MAX_ROWS || p.bytes >= CHUNK_MAX_BYTES
        };
        if full {
            self.flush_pending(index)?;
        }
        Ok(())
    }

    /// Writes the rows of `pending[index]` as one chunk.
    fn flush_pending(&mut self, index: usize) -> Result<(), RecordingError> {
        let Some(p) = self.pending.get_mut(index) else {
            return Ok(());
        };
        if p.rows.is_empty() {
            return Ok(());
        }
        let rows = std::mem::take(&mut p.rows);
        p.bytes = 0;
        let (store, entity_path, is_static) = (p.store, p.entity_path.clone(), p.is_static);
        let chunk_id = ChunkId::from_u128(self.next_id());
        let mut builder = Chunk::builder_with_id(chunk_id, entity_path);
        for (row_id, timepoint, batches) in rows {
            builder = builder.with_serialized_batches(row_id, timepoint, batches);
        }
        let chunk = builder.build().map_err(|e| encode_error("rrd chunk", e))?;
        debug_assert_eq!(chunk.is_static(), is_static);
        self.send(Job::Chunk(store, chunk))
    }

    /// Writes every pending row of store `store` (in the order their entities first appeared).
    pub(super) fn flush_store(&mut self, store: usize) -> Result<(), RecordingError> {
        for index in 0..self.pending.len() {
            if self.pending.get(index).is_some_and(|p| p.store == store) {
                self.flush_pending(index)?;
            }
        }
        Ok(())
    }

    /// Writes a message that is not data (the blueprint's activation).
    pub(super) fn write_command(&mut self, msg: &LogMsg) -> Result<(), RecordingError> {
        self.send(Job::Msg(msg.clone()))
    }

    /// Writes the pending rows, then waits for the writer thread to write them and the footer
    /// and to flush the file.
    pub(super) fn finish(mut self) -> Result<(), RecordingError> {
        for store in 0..self.store_ids.len() {
            self.flush_store(store)?;
        }
        self.join()
    }
}

impl Drop for RrdWriter {
    /// Without [`RrdWriter::finish`] (a failed run): the thread ends the file, which the caller
    /// deletes; it is waited for, so that the deletion comes after the last write.
    fn drop(&mut self) {
        self.join().ok();
    }
}
