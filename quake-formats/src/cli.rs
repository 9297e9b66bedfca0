//! What the command lines share: ericw-tools' single-dash spellings of long options, ericw-tools'
//! options a stage accepts without acting on them ([`ericw_accepted!`]), and (in
//! [`crate::progress::terminal`]) progress drawn as a bar.

/// Lets the process end quietly, as other command-line tools do, when whatever reads its
/// standard output stops reading (`slipgate wad list X.wad | head`): Rust starts programs with
/// SIGPIPE ignored, and a write to the closed pipe then makes `println!` panic. Call it first
/// thing in `main`.
pub fn end_quietly_on_closed_pipe() {
    #[cfg(unix)]
    {
        unsafe extern "C" {
            fn signal(signum: std::ffi::c_int, handler: usize) -> usize;
        }
        /// SIGPIPE's number, 13 on every Unix Rust builds for.
        const SIGPIPE: std::ffi::c_int = 13;
        /// `SIG_DFL`: the signal's default action (for SIGPIPE, ending the process).
        const SIG_DFL: usize = 0;
        // SAFETY: sets the disposition of one signal to its default, which needs no handler
        // code; called before the program starts threads or writes anything.
        unsafe {
            signal(SIGPIPE, SIG_DFL);
        }
    }
}

/// Whether an option was given on the command line: a flag set, or a value present.
pub trait Given {
    /// True when the option appeared.
    fn given(&self) -> bool;
}

impl Given for bool {
    fn given(&self) -> bool {
        *self
    }
}

impl<T> Given for Option<T> {
    fn given(&self) -> bool {
        self.is_some()
    }
}

impl<T> Given for Vec<T> {
    fn given(&self) -> bool {
        !self.is_empty()
    }
}

/// Declares a stage's ericw-tools options that it accepts without acting on them, so that a
/// compile profile written for ericw-tools runs unchanged: each is a hidden clap option (a
/// `bool` flag or an `Option<String>` value) with the note printed when it is given, saying
/// what Slipgate does instead. Flatten the struct into the stage's arguments and print
/// `notes()` when the stage runs.
///
/// Every ericw-tools tool takes the same options for how it reports (`-verbose`, `-nopercent`,
/// `-nolog`, `-lowpriority`...); `struct Name with reporting { ... }` adds them to the list.
#[macro_export]
macro_rules! ericw_accepted {
    ($(#[$meta:meta])* $vis:vis struct $name:ident with reporting { $($rest:tt)* }) => {
        $crate::ericw_accepted! {
            $(#[$meta])*
            $vis struct $name {
                verbose: bool => "the summary is the same either way",
                noverbose: bool => "the summary is the same either way",
                quiet: bool => "the summary is the same either way",
                nopercent: bool => "progress is drawn only when standard error is a terminal",
                noprogress: bool => "progress is drawn only when standard error is a terminal",
                nostat: bool => "the summary is the same either way",
                nocolor: bool => "Slipgate writes no colour codes",
                log: bool => "Slipgate writes no log file; redirect its output",
                nolog: bool => "Slipgate writes no log file",
                lowpriority: bool => "Slipgate runs at the priority it is started with (use nice)",
                $($rest)*
            }
        }
    };
    ($(#[$meta:meta])* $vis:vis struct $name:ident {
        $( $field:ident : $ty:ty => $note:literal ),* $(,)?
    }) => {
        $(#[$meta])*
        #[derive(clap::Args, Debug, Clone, Default)]
        $vis struct $name {
            $(
                #[doc = $note]
                #[arg(long = stringify!($field), hide = true)]
                $field: $ty,
            )*
        }

        impl $name {
            /// One line for each of these options given: its name and what Slipgate does instead.
            pub fn notes(&self) -> Vec<String> {
                let mut notes = Vec::new();
                $(
                    if $crate::cli::Given::given(&self.$field) {
                        notes.push(format!("-{} has no effect: {}", stringify!($field), $note));
                    }
                )*
                notes
            }
        }
    };
}

/// ericw-tools writes long options with one dash (`-extra4`, `-2psb`); clap wants two. Negative
/// numbers (`-100`, `-1e5`) and short flags (`-h`) are left alone, but for ericw-tools' `-v`,
/// its tools' short form of `-verbose`. The first word (the program name) is kept as it is.
pub fn normalise_single_dash(args: impl Iterator<Item = String>) -> Vec<String> {
    args.enumerate()
        .map(|(i, a)| {
            if i > 0 && a == "-v" {
                return "--verbose".to_string();
            }
            let name = a.strip_prefix('-').unwrap_or_default();
            let is_ericw_long = i > 0
                && name.len() > 1
                && !name.starts_with('-')
                && name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
                && (name.starts_with(|c: char| c.is_ascii_alphabetic())
                    // A name may start with a digit (`-2psb`) as long as it is not a number.
                    || (name.contains(|c: char| c.is_ascii_alphabetic())
                        && name.parse::<f64>().is_err()));
            if is_ericw_long { format!("-{a}") } else { a }
        })
        .collect()
}

/// Options whose value may be left out (`--bounce [N]`, `--litwater [N]`: ericw-tools'
/// spelling), declared with `require_equals` and named in `options` with the most numbers each
/// takes, take the numbers that follow them as their value: `--bounce 2` becomes `--bounce=2`
/// and `--lightgrid_dist 16 16 32` becomes `--lightgrid_dist=16 16 32`, while `--bounce
/// map.bsp` leaves the file as the positional argument.
pub fn join_optional_values(
    args: impl IntoIterator<Item = String>,
    options: &[(&str, usize)],
) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    // Numbers the last option may still take.
    let mut open = 0;
    for a in args {
        // A minus sign may lead: `--soft -1` is ericw-tools' "half a luxel".
        let digits = a.strip_prefix('-').unwrap_or(&a);
        let number = !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit() || c == '.');
        match out.last_mut() {
            Some(prev) if open > 0 && number => {
                prev.push(if prev.contains('=') { ' ' } else { '=' });
                prev.push_str(&a);
                open -= 1;
            }
            _ => {
                open = options
                    .iter()
                    .find(|(name, _)| *name == a)
                    .map_or(0, |&(_, n)| n);
                out.push(a);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_number_after_an_optional_value_option_is_its_value() {
        let args = ["light", "--bounce", "2", "--soft", "x.bsp", "--other", "3"];
        let options = [("--bounce", 1), ("--soft", 1), ("--dist", 3)];
        let out = join_optional_values(args.iter().map(|s| s.to_string()), &options);
        assert_eq!(
            out,
            ["light", "--bounce=2", "--soft", "x.bsp", "--other", "3"]
        );
        let three = ["light", "--dist", "16", "16", "32.5", "7", "x.bsp"];
        let out = join_optional_values(three.iter().map(|s| s.to_string()), &options);
        assert_eq!(out, ["light", "--dist=16 16 32.5", "7", "x.bsp"]);
        let negative = ["light", "--soft", "-1", "x.bsp"];
        let out = join_optional_values(negative.iter().map(|s| s.to_string()), &options);
        assert_eq!(out, ["light", "--soft=-1", "x.bsp"]);
    }

    #[test]
    fn single_dash_long_options_become_double_dash() {
        let args = [
            "slipgate", "light", "-extra4", "-soft", "-h", "--pos", "-100", "-1e5", "-2psb", "-v",
            "x.bsp",
        ];
        let out = normalise_single_dash(args.iter().map(|s| s.to_string()));
        assert_eq!(
            out,
            [
                "slipgate",
                "light",
                "--extra4",
                "--soft",
                "-h",
                "--pos",
                "-100",
                "-1e5",
                "--2psb",
                "--verbose",
                "x.bsp"
            ]
        );
    }
}
