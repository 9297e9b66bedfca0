//! Manifests: what a batch (or one shard of it) built, and the check that joins the shards.
//!
//! Each run writes `slipgate-manifest.json` (or `slipgate-manifest-K-of-N.json` for a shard) in
//! its output folder: every map of the project, the maps this run built, each with its stages
//! (keys, cached or not) and its outputs' hashes. [`collect`] reads the manifests under some
//! folders and checks that every map of the project was built exactly once, without failing,
//! and that every output beside a manifest still has the hash the manifest gives.

use crate::hash::hash_bytes;
use crate::stages::MapOutcome;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One shard of N: runner `index` (1-based) of `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("{s:?}: a shard is K/N with 1 <= K <= N, e.g. 2/3");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// Whether the map at `position` in the project's sorted map list is this shard's: the maps
    /// are dealt round robin in name order, so the split depends only on the list of names.
    pub fn takes(&self, position: usize) -> bool {
        position % self.count == self.index - 1
    }

    pub fn manifest_name(shard: Option<Shard>) -> String {
        match shard {
            Some(s) => format!("slipgate-manifest-{}-of-{}.json", s.index, s.count),
            None => "slipgate-manifest.json".into(),
        }
    }
}

#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Manifest {
    /// The Slipgate version that wrote it.
    pub version: String,
    pub shard: Option<Shard>,
    /// Every map of the project, whichever shard builds it.
    pub project_maps: Vec<String>,
    /// The maps this run built (or tried to).
    pub built: Vec<MapOutcome>,
}

#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: {message}", path.display())]
    Json { path: PathBuf, message: String },
    #[error("no slipgate-manifest*.json under {dirs}")]
    NoManifests { dirs: String },
}

impl Manifest {
    pub fn write(&self, path: &Path) -> Result<(), ManifestError> {
        let json = serde_json::to_string_pretty(self).map_err(|e| ManifestError::Json {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        quake_formats::fsutil::write_atomic(path, json.as_bytes()).map_err(|e| {
            ManifestError::Json {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        })
    }

    fn read(path: &Path) -> Result<Manifest, ManifestError> {
        let text = std::fs::read_to_string(path).map_err(|source| ManifestError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| ManifestError::Json {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }
}

/// What [`collect`] found.
#[derive(Debug, Default)]
pub struct Collected {
    pub manifests: Vec<PathBuf>,
    /// Maps built, each with the manifest that has it.
    pub maps: BTreeMap<String, PathBuf>,
    /// Everything wrong, one line each; empty when the shards make the whole project.
    pub problems: Vec<String>,
}

/// Join the manifests found under `dirs` (searched recursively).
pub fn collect(dirs: &[PathBuf]) -> Result<Collected, ManifestError> {
    let mut found = Vec::new();
    let is_manifest = |path: &Path| {
        path.file_name()
            .map(|n| n.to_string_lossy())
            .is_some_and(|n| n.starts_with("slipgate-manifest") && n.ends_with(".json"))
    };
    for dir in dirs {
        crate::walk::files_under(dir, &is_manifest, &mut found)
            .map_err(|(path, source)| ManifestError::Io { path, source })?;
    }
    found.sort();
    if found.is_empty() {
        return Err(ManifestError::NoManifests {
            dirs: dirs
                .iter()
                .map(|d| d.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let mut collected = Collected::default();
    let mut project: Option<(Vec<String>, PathBuf)> = None;
    for path in &found {
        let manifest = Manifest::read(path)?;
        match &project {
            None => project = Some((manifest.project_maps.clone(), path.clone())),
            Some((maps, first)) if *maps != manifest.project_maps => {
                collected.problems.push(format!(
                    "{} lists other project maps than {}",
                    path.display(),
                    first.display()
                ));
            }
            Some(_) => {}
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        for map in &manifest.built {
            check_map(map, dir, path, &mut collected);
        }
        collected.manifests.push(path.clone());
    }
    for map in project.map(|(maps, _)| maps).unwrap_or_default() {
        if !collected.maps.contains_key(&map) {
            collected
                .problems
                .push(format!("{map}: missing (no manifest built it)"));
        }
    }
    Ok(collected)
}

fn check_map(map: &MapOutcome, dir: &Path, manifest: &Path, collected: &mut Collected) {
    if let Some(other) = collected.maps.get(&map.map) {
        collected.problems.push(format!(
            "{}: built twice ({} and {})",
            map.map,
            other.display(),
            manifest.display()
        ));
        return;
    }
    collected
        .maps
        .insert(map.map.clone(), manifest.to_path_buf());
    if let Some(failure) = &map.failure {
        collected
            .problems
            .push(format!("{}: failed at {failure}", map.map));
    }
    for (output, hash) in &map.outputs {
        let path = dir.join(output);
        match std::fs::read(&path) {
            Ok(bytes) if hash_bytes(&bytes) == *hash => {}
            Ok(_) => collected.problems.push(format!(
                "{}: {} does not match its hash in {}",
                map.map,
                path.display(),
                manifest.display()
            )),
            Err(e) => collected
                .problems
                .push(format!("{}: {}: {e}", map.map, path.display())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_deal_the_maps_round_robin() {
        let shards: Vec<Shard> = ["1/3", "2/3", "3/3"]
            .iter()
            .map(|s| s.parse().expect("shard"))
            .collect();
        for position in 0..10 {
            let takers = shards.iter().filter(|s| s.takes(position)).count();
            assert_eq!(takers, 1, "map {position}");
        }
        assert!(shards[1].takes(4));
        assert!("0/3".parse::<Shard>().is_err() && "4/3".parse::<Shard>().is_err());
        assert!("2".parse::<Shard>().is_err());
    }
}
