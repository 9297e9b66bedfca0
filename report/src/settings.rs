//! The quality settings of each stage, and the matching options of each tool.

/// A stage of the pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Stage {
    /// Compiling a `.map` to BSP and portal file.
    Bsp,
    /// Computing the PVS.
    Vis,
    /// Computing lightmaps.
    Light,
    /// Drawing the map with the software viewer.
    View,
}

impl Stage {
    /// Every stage, in pipeline order.
    pub const ALL: [Stage; 4] = [Stage::Bsp, Stage::Vis, Stage::Light, Stage::View];

    /// The stage's command-line name (`bsp`), as in file names and tables.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Bsp => "bsp",
            Stage::Vis => "vis",
            Stage::Light => "light",
            Stage::View => "view",
        }
    }

    /// What a plot's error axis shows.
    pub fn error_name(self) -> &'static str {
        match self {
            Stage::Bsp => "cracks + player-hull moves that disagree with the brushes",
            Stage::Vis => "PVS / sampled visible pairs",
            Stage::Light => "RMSE against --reference, drawn luxels (8-bit levels)",
            Stage::View => "mean difference against the exact renderer (of 255)",
        }
    }

    /// What a plot's time axis shows.
    pub fn time_name(self) -> &'static str {
        match self {
            Stage::View => "ms per frame (flythrough)",
            _ => "wall seconds (whole process, best of N)",
        }
    }
}

/// Whose implementation ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tool {
    /// Slipgate's own stages.
    Slipgate,
    /// The anchor: ericw-tools' `qbsp`, `vis` and `light`.
    EricwTools,
}

impl Tool {
    /// The name tables and plots give the tool.
    pub fn name(self) -> &'static str {
        match self {
            Tool::Slipgate => "Slipgate",
            Tool::EricwTools => "ericw-tools",
        }
    }
}

/// One quality setting of a stage: its name (Slipgate's options, as a mapper writes them) and
/// what it is for each tool.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    pub stage: Stage,
    pub name: String,
    /// Slipgate's options.
    pub ours: Vec<String>,
    /// ericw-tools' options; `None` when it has no such stage.
    pub theirs: Option<Vec<String>>,
}

impl Setting {
    /// A file-name-safe key: `--extra4 --soft` is `extra4-soft`.
    pub fn key(&self) -> String {
        let words: Vec<&str> = self
            .name
            .split_whitespace()
            .map(|w| w.trim_start_matches('-'))
            .collect();
        format!("{}-{}", self.stage.name(), words.join("-"))
    }

    /// What of a light setting's output is measured, and so which reference it is measured
    /// against.
    pub fn light_measure(&self) -> LightMeasure {
        let value_of = |flag: &str| {
            let at = self.ours.iter().position(|o| o == flag)?;
            self.ours.get(at + 1)?.parse().ok()
        };
        if let Some(world_units_per_luxel) = value_of("--world_units_per_luxel") {
            LightMeasure::OwnGrids {
                world_units_per_luxel,
            }
        } else if self.ours.iter().any(|o| o == "--lightgrid") {
            LightMeasure::LightGrid
        } else {
            LightMeasure::Lightmaps {
                bounce: self.ours.iter().any(|o| o.starts_with("--bounce")),
            }
        }
    }
}

/// What of a light run's output is measured, against a reference that computes the same with
/// light's `Quality::Reference`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LightMeasure {
    /// The 16-texel lightmaps, against the reference's (with one bounce when the setting
    /// bounces).
    Lightmaps {
        /// The setting bounces light.
        bounce: bool,
    },
    /// The lightmaps on the faces' own world-aligned grids (`DECOUPLED_LM`), against the
    /// reference lit on the same grids.
    OwnGrids {
        /// Map units per luxel of those grids.
        world_units_per_luxel: f64,
    },
    /// The light grid's points (`LIGHTGRID_OCTREE`), against the reference's grid of the same
    /// points.
    LightGrid,
}

impl LightMeasure {
    /// The reference's name in the report's text.
    pub fn reference_name(self) -> String {
        match self {
            LightMeasure::Lightmaps { bounce: false } => "direct".into(),
            LightMeasure::Lightmaps { bounce: true } => "with bounce".into(),
            LightMeasure::OwnGrids {
                world_units_per_luxel,
            } => format!("on own grids of {world_units_per_luxel} units"),
            LightMeasure::LightGrid => "light grid".into(),
        }
    }

    /// What one unit of the measure's count is, as its table cell says.
    pub fn counted(self) -> &'static str {
        match self {
            LightMeasure::Lightmaps { .. } => "luxels",
            LightMeasure::OwnGrids { .. } => "own-grid luxels",
            LightMeasure::LightGrid => "grid samples",
        }
    }
}

/// Light's settings: each quality mode alone, `slipgate build --final`'s combination, and the
/// modes of today's engines: lightmaps on the faces' own grids, the light grid, and the
/// output-only lumps and files (measured as the default light).
pub const LIGHT_SETTINGS: [&str; 9] = [
    "default",
    "--extra",
    "--extra4",
    "--soft",
    "--bounce",
    "--extra4 --soft --bounce",
    "--world_units_per_luxel 8",
    "--lightgrid",
    "--bspxlit --lux --hdr",
];

/// The viewer's span steps (pixels between exact perspective divides; 1 divides every pixel).
pub const SPAN_STEPS: [u32; 4] = [1, 8, 16, 32];

/// Every setting of every stage, in the order they run.
pub fn all_settings() -> Vec<Setting> {
    let words = |s: &str| -> Vec<String> {
        s.split_whitespace()
            .filter(|w| *w != "default")
            .map(str::to_string)
            .collect()
    };
    // ericw-tools spells long options with one dash; values stay as they are.
    let single_dash = |s: &str| -> Vec<String> {
        let one_dash = |w: &String| w.strip_prefix('-').unwrap_or(w).to_string();
        words(s).iter().map(one_dash).collect()
    };
    let mut all = vec![Setting {
        stage: Stage::Bsp,
        name: "default".into(),
        ours: Vec::new(),
        theirs: Some(Vec::new()),
    }];
    for name in ["fast", "full"] {
        let flag = if name == "fast" { "--fast" } else { "" };
        all.push(Setting {
            stage: Stage::Vis,
            name: name.into(),
            ours: words(flag),
            theirs: Some(single_dash(flag)),
        });
    }
    for name in LIGHT_SETTINGS {
        all.push(Setting {
            stage: Stage::Light,
            name: name.into(),
            ours: words(name),
            theirs: Some(single_dash(name)),
        });
    }
    for step in SPAN_STEPS {
        all.push(Setting {
            stage: Stage::View,
            name: format!("span step {step}"),
            ours: vec!["--span-step".into(), step.to_string()],
            theirs: None,
        });
    }
    all
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_have_unique_keys_and_matching_ericw_spellings() {
        let all = all_settings();
        let mut keys: Vec<String> = all.iter().map(Setting::key).collect();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), all.len());
        let final_light = all
            .iter()
            .find(|s| s.key() == "light-extra4-soft-bounce")
            .expect("the --final light setting");
        assert_eq!(final_light.ours, ["--extra4", "--soft", "--bounce"]);
        assert_eq!(
            final_light.theirs.as_deref(),
            Some(&["-extra4".to_string(), "-soft".into(), "-bounce".into()][..])
        );
        assert_eq!(
            final_light.light_measure(),
            LightMeasure::Lightmaps { bounce: true }
        );
        let decoupled = all
            .iter()
            .find(|s| s.key() == "light-world_units_per_luxel-8")
            .expect("decoupled lightmaps");
        assert_eq!(
            decoupled.theirs.as_deref(),
            Some(&["-world_units_per_luxel".to_string(), "8".into()][..])
        );
        assert_eq!(
            decoupled.light_measure(),
            LightMeasure::OwnGrids {
                world_units_per_luxel: 8.0
            }
        );
        let grid = all.iter().find(|s| s.key() == "light-lightgrid");
        assert_eq!(
            grid.map(Setting::light_measure),
            Some(LightMeasure::LightGrid)
        );
        let outputs = all.iter().find(|s| s.key() == "light-bspxlit-lux-hdr");
        assert_eq!(
            outputs.map(Setting::light_measure),
            Some(LightMeasure::Lightmaps { bounce: false })
        );
        let fast = all
            .iter()
            .find(|s| s.key() == "vis-fast")
            .expect("fast vis");
        assert_eq!(fast.theirs.as_deref(), Some(&["-fast".to_string()][..]));
    }
}
