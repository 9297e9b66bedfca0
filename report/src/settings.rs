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
            Stage::Light => "RMSE against --reference (8-bit levels)",
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

    /// Whether light's reference for this setting must bounce too.
    pub fn bounces(&self) -> bool {
        self.ours.iter().any(|o| o.starts_with("--bounce"))
    }
}

/// Light's settings: each mode alone, and `slipgate build --final`'s combination.
pub const LIGHT_SETTINGS: [&str; 6] = [
    "default",
    "--extra",
    "--extra4",
    "--soft",
    "--bounce",
    "--extra4 --soft --bounce",
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
    // ericw-tools spells long options with one dash.
    let single_dash = |s: &str| -> Vec<String> { words(s).iter().map(|w| w[1..].into()).collect() };
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
        assert!(final_light.bounces());
        let fast = all
            .iter()
            .find(|s| s.key() == "vis-fast")
            .expect("fast vis");
        assert_eq!(fast.theirs.as_deref(), Some(&["-fast".to_string()][..]));
    }
}
