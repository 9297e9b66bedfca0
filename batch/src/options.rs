//! Stage options written as one string, the way compile profiles and LibreQuake's per-map
//! settings write them (`"-extra4 -soft"`), turned into the words each stage's own command
//! line parses, so a batch runs exactly what the stage commands would.

use clap::{Args, FromArgMatches};
use quake_formats::cli::normalise_single_dash;

/// Command-line words (the program's name first) as the stages' commands parse them: ericw-tools'
/// single-dash spellings given two dashes, and a number after an option whose value is optional
/// (`-bounce 2`, `-litwater 0`) joined to it.
pub fn command_words(words: impl Iterator<Item = String>) -> Vec<String> {
    let words = normalise_single_dash(words);
    bsp_compiler::cli::join_optional_values(light::cli::join_optional_values(words))
}

/// A stage's option string as the words its command takes (ericw-tools' spellings accepted).
pub fn stage_words(options: &str) -> Vec<String> {
    let words =
        std::iter::once(String::new()).chain(options.split_whitespace().map(str::to_string));
    command_words(words).into_iter().skip(1).collect()
}

/// Parse a stage's own arguments (`A`: the stage's `cli::Args`) from words.
pub fn parse_stage<A: Args + FromArgMatches>(
    name: &'static str,
    words: &[String],
) -> Result<A, clap::Error> {
    let command = A::augment_args(clap::Command::new(name).no_binary_name(true));
    let matches = command.try_get_matches_from(words)?;
    A::from_arg_matches(&matches)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stage_options_take_ericw_spellings() {
        assert_eq!(
            stage_words("-leaktest  -maxnodesize 512"),
            ["--leaktest", "--maxnodesize", "512"]
        );
        assert_eq!(stage_words("-bounce 2 -lit"), ["--bounce=2", "--lit"]);
        assert!(stage_words("  ").is_empty());
        let mut words = vec!["x.bsp".to_string()];
        words.extend(stage_words("-bounce 2 -lit -threads 1"));
        let light: light::cli::Args = parse_stage("light", &words).expect("light options parse");
        assert_eq!(
            (light.overrides.bounce, light.lit, light.threads),
            (Some(2), true, Some(1))
        );
    }
}
