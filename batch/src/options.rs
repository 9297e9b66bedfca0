//! Stage options written as one string, the way compile profiles and LibreQuake's per-map
//! settings write them (`"-extra4 -soft"`), turned into the words each stage's own command
//! line parses, so a batch runs exactly what the stage commands would.

use clap::{Args, FromArgMatches};

/// ericw-tools writes long options with one dash (`-extra4`); clap wants two. Negative numbers
/// and short flags (`-h`) are left alone. The first word (the program name) is kept as it is.
pub fn normalise_single_dash(args: impl Iterator<Item = String>) -> Vec<String> {
    args.enumerate()
        .map(|(i, a)| {
            let is_ericw_long = i > 0
                && a.len() > 2
                && a.starts_with('-')
                && !a.starts_with("--")
                && a[1..].starts_with(|c: char| c.is_ascii_alphabetic())
                && a[1..]
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if is_ericw_long { format!("-{a}") } else { a }
        })
        .collect()
}

/// A stage's option string as the words its command takes (ericw-tools' spellings accepted).
pub fn stage_words(options: &str) -> Vec<String> {
    let words =
        std::iter::once(String::new()).chain(options.split_whitespace().map(str::to_string));
    let normalised = light::cli::join_optional_values(normalise_single_dash(words));
    normalised.into_iter().skip(1).collect()
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
    fn single_dash_long_options_become_double_dash() {
        let args = [
            "slipgate", "light", "-extra4", "-soft", "-h", "--pos", "-100", "x.bsp",
        ];
        let out = normalise_single_dash(args.iter().map(|s| s.to_string()));
        assert_eq!(
            out,
            [
                "slipgate", "light", "--extra4", "--soft", "-h", "--pos", "-100", "x.bsp"
            ]
        );
    }

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
