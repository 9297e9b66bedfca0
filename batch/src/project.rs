//! What a batch builds: a project file (TOML) listing maps or globs, default options per stage
//! and per-map overrides; or a folder, every `.map` under it with the defaults.
//!
//! ```toml
//! maps = ["maps/*.map", "maps/extra/e1m1.map"]  # globs, relative to this file
//! output = "build"                              # default: each BSP beside its map
//! cache = ".slipgate-cache"                     # the default
//!
//! [defaults]                                    # each stage's options, as its command takes them
//! bsp = "-wad-dir wads"
//! light = "-extra4 -soft"
//! preview = "--size 320x240"                    # or false: no preview pictures
//!
//! [map."maps/e1m1.map"]                         # replaces the defaults it names, for one map
//! light = "-extra4 -soft -bounce"
//! ```

use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The name of the cache folder, beside the project file (or in the project folder).
pub const DEFAULT_CACHE_DIR: &str = ".slipgate-cache";

#[derive(Debug, thiserror::Error)]
pub enum ProjectError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The parser's message (several lines, pointing at the place).
    #[error("{}: {message}", path.display())]
    Toml { path: PathBuf, message: String },
    #[error("{}: bad glob {pattern:?}: {message}", path.display())]
    Glob {
        path: PathBuf,
        pattern: String,
        message: String,
    },
    #[error("{}: [map.{name:?}] names no map the project builds", path.display())]
    UnknownOverride { path: PathBuf, name: String },
    #[error("{}: {} lies outside the project folder", path.display(), map.display())]
    Outside { path: PathBuf, map: PathBuf },
    #[error("{}: no .map files to build", path.display())]
    NoMaps { path: PathBuf },
}

/// Options for each stage, as option strings; `None` leaves the level below in force.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSettings {
    pub bsp: Option<String>,
    pub vis: Option<String>,
    pub light: Option<String>,
    pub preview: Option<PreviewSetting>,
}

/// `preview = false` (none), `true` (the default picture) or the view command's options.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum PreviewSetting {
    Enabled(bool),
    Options(String),
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProjectFile {
    #[serde(default)]
    maps: Vec<String>,
    output: Option<PathBuf>,
    cache: Option<PathBuf>,
    #[serde(default)]
    defaults: StageSettings,
    #[serde(default)]
    map: BTreeMap<String, StageSettings>,
}

/// One map's options, every stage's resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MapOptions {
    pub bsp: String,
    pub vis: String,
    pub light: String,
    /// The view command's options, `None` for no preview.
    pub preview: Option<String>,
}

impl MapOptions {
    fn with(&self, settings: &StageSettings) -> MapOptions {
        let pick = |over: &Option<String>, base: &String| over.clone().unwrap_or(base.clone());
        MapOptions {
            bsp: pick(&settings.bsp, &self.bsp),
            vis: pick(&settings.vis, &self.vis),
            light: pick(&settings.light, &self.light),
            preview: match &settings.preview {
                None => self.preview.clone(),
                Some(PreviewSetting::Enabled(false)) => None,
                Some(PreviewSetting::Enabled(true)) => Some(String::new()),
                Some(PreviewSetting::Options(o)) => Some(o.clone()),
            },
        }
    }
}

impl Default for MapOptions {
    fn default() -> Self {
        MapOptions {
            bsp: String::new(),
            vis: String::new(),
            light: String::new(),
            preview: Some(String::new()),
        }
    }
}

/// One map to build.
#[derive(Debug, Clone)]
pub struct MapJob {
    /// Path relative to the project folder, with `/` separators: the map's name everywhere
    /// (shards, manifests, the summary) and where its outputs go under the output folder.
    pub name: String,
    pub path: PathBuf,
    pub options: MapOptions,
}

impl MapJob {
    /// Where an output with this extension goes, under `output_dir`.
    pub fn output(&self, output_dir: &Path, extension: &str) -> PathBuf {
        output_dir.join(self.output_name(extension))
    }

    /// The output's path relative to the output folder (`/` separators).
    pub fn output_name(&self, extension: &str) -> String {
        let stem = self.name.strip_suffix(".map").unwrap_or(&self.name);
        format!("{stem}.{extension}")
    }
}

/// A project resolved: its folder, where outputs and the cache go, and its maps, sorted by name.
#[derive(Debug, Clone)]
pub struct Project {
    pub root: PathBuf,
    pub output_dir: PathBuf,
    pub cache_dir: PathBuf,
    pub maps: Vec<MapJob>,
}

impl Project {
    /// Load a project file, or take every `.map` under a folder.
    pub fn load(path: &Path) -> Result<Project, ProjectError> {
        if path.is_dir() {
            return Project::from_folder(path);
        }
        let io = |source| ProjectError::Io {
            path: path.to_path_buf(),
            source,
        };
        let text = std::fs::read_to_string(path).map_err(io)?;
        let file: ProjectFile = toml::from_str(&text).map_err(|e| ProjectError::Toml {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let root = match path.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut names = Vec::new();
        for pattern in &file.maps {
            names.extend(glob_maps(path, &root, pattern)?);
        }
        let defaults = MapOptions::default().with(&file.defaults);
        let project = Project {
            output_dir: root.join(file.output.unwrap_or_default()),
            cache_dir: root.join(file.cache.unwrap_or(DEFAULT_CACHE_DIR.into())),
            maps: jobs(&root, names, &defaults, &file.map),
            root,
        };
        if let Some(name) = file
            .map
            .keys()
            .find(|n| !project.maps.iter().any(|m| &m.name == *n))
        {
            return Err(ProjectError::UnknownOverride {
                path: path.to_path_buf(),
                name: name.clone(),
            });
        }
        if project.maps.is_empty() {
            return Err(ProjectError::NoMaps {
                path: path.to_path_buf(),
            });
        }
        Ok(project)
    }

    fn from_folder(root: &Path) -> Result<Project, ProjectError> {
        let is_map = |path: &Path| {
            path.extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("map"))
        };
        let mut paths = Vec::new();
        crate::walk::files_under(root, &is_map, &mut paths)
            .map_err(|(path, source)| ProjectError::Io { path, source })?;
        let names = paths.iter().map(|p| relative_name(root, p)).collect();
        let maps = jobs(root, names, &MapOptions::default(), &BTreeMap::new());
        if maps.is_empty() {
            return Err(ProjectError::NoMaps {
                path: root.to_path_buf(),
            });
        }
        Ok(Project {
            root: root.to_path_buf(),
            output_dir: root.to_path_buf(),
            cache_dir: root.join(DEFAULT_CACHE_DIR),
            maps,
        })
    }
}

fn jobs(
    root: &Path,
    mut names: Vec<String>,
    defaults: &MapOptions,
    overrides: &BTreeMap<String, StageSettings>,
) -> Vec<MapJob> {
    names.sort();
    names.dedup();
    names
        .into_iter()
        .map(|name| MapJob {
            path: root.join(&name),
            options: overrides
                .get(&name)
                .map_or_else(|| defaults.clone(), |o| defaults.with(o)),
            name,
        })
        .collect()
}

/// A path under `root` as a map name: relative, `/`-separated.
fn relative_name(root: &Path, path: &Path) -> String {
    let relative = path.strip_prefix(root).unwrap_or(path);
    relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy())
        .collect::<Vec<_>>()
        .join("/")
}

fn glob_maps(file: &Path, root: &Path, pattern: &str) -> Result<Vec<String>, ProjectError> {
    let bad = |message: String| ProjectError::Glob {
        path: file.to_path_buf(),
        pattern: pattern.to_string(),
        message,
    };
    let full = root.join(pattern);
    let paths = glob::glob(&full.to_string_lossy()).map_err(|e| bad(e.to_string()))?;
    let canonical = |p: &Path| {
        p.canonicalize().map_err(|source| ProjectError::Io {
            path: p.to_path_buf(),
            source,
        })
    };
    let root = canonical(root)?;
    let mut names = Vec::new();
    for entry in paths {
        let path = entry.map_err(|e| bad(e.to_string()))?;
        if path.is_file() {
            let path = canonical(&path)?;
            if !path.starts_with(&root) {
                // Its outputs would land outside the output folder.
                return Err(ProjectError::Outside {
                    path: file.to_path_buf(),
                    map: path,
                });
            }
            names.push(relative_name(&root, &path));
        }
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_replace_only_the_stages_they_name() {
        let dir = tempfile::tempdir().expect("temp dir");
        for name in ["a.map", "sub/b.map", "sub/c.txt"] {
            let path = dir.path().join(name);
            std::fs::create_dir_all(path.parent().expect("parent")).expect("mkdir");
            std::fs::write(&path, "{}").expect("write");
        }
        let project_file = dir.path().join("project.toml");
        std::fs::write(
            &project_file,
            r#"
maps = ["*.map", "sub/*.map"]
output = "out"
[defaults]
light = "-extra4"
preview = "--size 64x48"
[map."sub/b.map"]
light = "-soft"
preview = false
"#,
        )
        .expect("write");
        let project = Project::load(&project_file).expect("loads");
        let names: Vec<_> = project.maps.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["a.map", "sub/b.map"]);
        assert_eq!(project.maps[0].options.light, "-extra4");
        assert_eq!(
            project.maps[0].options.preview.as_deref(),
            Some("--size 64x48")
        );
        assert_eq!(project.maps[1].options.light, "-soft");
        assert_eq!(project.maps[1].options.preview, None);
        assert_eq!(project.output_dir, dir.path().join("out"));
        assert_eq!(project.maps[1].output_name("bsp"), "sub/b.bsp");

        let folder = Project::load(dir.path()).expect("folder loads");
        assert_eq!(folder.maps.len(), 2);
        assert_eq!(folder.maps[1].options, MapOptions::default());
    }

    #[test]
    fn an_override_for_an_unknown_map_is_an_error() {
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::write(dir.path().join("a.map"), "{}").expect("write");
        let file = dir.path().join("p.toml");
        std::fs::write(
            &file,
            "maps = [\"a.map\"]\n[map.\"b.map\"]\nvis = \"-fast\"\n",
        )
        .expect("write");
        let err = Project::load(&file).expect_err("unknown override");
        assert!(err.to_string().contains("b.map"), "{err}");
        let inner = dir.path().join("sub").join("p.toml");
        std::fs::create_dir_all(dir.path().join("sub")).expect("mkdir");
        std::fs::write(&inner, "maps = [\"../a.map\"]\n").expect("write");
        let err = Project::load(&inner).expect_err("outside");
        assert!(err.to_string().contains("outside the project"), "{err}");
    }
}
