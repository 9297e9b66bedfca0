//! The stage cache: content-addressed blobs and, per stage key, a record of what the stage made.
//!
//! ```text
//! CACHE/blobs/ab/abcdef...   one file per distinct output, named by its SHA-256
//! CACHE/stages/<key>.json    a finished stage: its outputs (name -> blob hash), counts, seconds
//! ```
//!
//! A stage's blobs are written before its record, each atomically, so an interrupted batch leaves
//! only whole records of finished stages: the next run picks up after them.

use crate::hash::hash_bytes;
use quake_formats::fsutil::write_atomic;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum CacheError {
    #[error("cache {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cache {}: {message}", path.display())]
    Format { path: PathBuf, message: String },
    #[error("cache blob {hash} is missing or damaged")]
    Blob { hash: String },
}

/// What a finished stage made.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct StageRecord {
    /// Output name (`bsp`, `prt`, `lit`, `png`) and the hash of its blob.
    pub outputs: BTreeMap<String, String>,
    /// What the stage counted, for the summary.
    pub counts: String,
    /// How long it took when it ran.
    pub seconds: f64,
}

pub struct Cache {
    dir: PathBuf,
}

impl Cache {
    pub fn new(dir: &Path) -> Cache {
        Cache {
            dir: dir.to_path_buf(),
        }
    }

    fn blob_path(&self, hash: &str) -> PathBuf {
        let prefix = hash.get(..2).unwrap_or("00");
        self.dir.join("blobs").join(prefix).join(hash)
    }

    fn record_path(&self, key: &str) -> PathBuf {
        self.dir.join("stages").join(format!("{key}.json"))
    }

    /// Store `bytes`, returning their hash.
    pub fn put_blob(&self, bytes: &[u8]) -> Result<String, CacheError> {
        let hash = hash_bytes(bytes);
        let path = self.blob_path(&hash);
        if !path.is_file() {
            create_parent(&path)?;
            write_atomic(&path, bytes).map_err(|e| CacheError::Format {
                path: path.clone(),
                message: e.to_string(),
            })?;
        }
        Ok(hash)
    }

    /// The blob with this hash, checked against it.
    pub fn blob(&self, hash: &str) -> Result<Vec<u8>, CacheError> {
        std::fs::read(self.blob_path(hash))
            .ok()
            .filter(|bytes| hash_bytes(bytes) == hash)
            .ok_or_else(|| CacheError::Blob {
                hash: hash.to_string(),
            })
    }

    /// The record of a finished stage with this key whose blobs are all still there.
    pub fn record(&self, key: &str) -> Option<StageRecord> {
        let text = std::fs::read_to_string(self.record_path(key)).ok()?;
        let record: StageRecord = serde_json::from_str(&text).ok()?;
        record
            .outputs
            .values()
            .all(|hash| self.blob_path(hash).is_file())
            .then_some(record)
    }

    pub fn put_record(&self, key: &str, record: &StageRecord) -> Result<(), CacheError> {
        let path = self.record_path(key);
        create_parent(&path)?;
        let json = serde_json::to_string_pretty(record).map_err(|e| CacheError::Format {
            path: path.clone(),
            message: e.to_string(),
        })?;
        write_atomic(&path, json.as_bytes()).map_err(|e| CacheError::Format {
            path,
            message: e.to_string(),
        })
    }
}

fn create_parent(path: &Path) -> Result<(), CacheError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|source| CacheError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_need_their_blobs() {
        let dir = tempfile::tempdir().expect("temp dir");
        let cache = Cache::new(dir.path());
        let hash = cache.put_blob(b"bsp bytes").expect("blob");
        assert_eq!(cache.blob(&hash).expect("read back"), b"bsp bytes");
        let record = StageRecord {
            outputs: BTreeMap::from([("bsp".to_string(), hash.clone())]),
            counts: "1 face".into(),
            seconds: 0.5,
        };
        cache.put_record("k", &record).expect("record");
        assert_eq!(cache.record("k"), Some(record));
        assert_eq!(cache.record("other"), None);
        std::fs::remove_file(cache.blob_path(&hash)).expect("remove");
        assert_eq!(
            cache.record("k"),
            None,
            "a record whose blob is gone is no hit"
        );
    }
}
