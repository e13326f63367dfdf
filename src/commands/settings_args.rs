//! The settings of a run as command-line flags, made from the library's schema
//! ([`crate::pipeline::schema::SETTINGS`]): one flag per setting with its help, value name,
//! choices and default, the selection's rules exclusive of each other (partners required
//! together); the flags given go to [`SmoothSettings::from_texts`], which checks them as it
//! checks every front end's. `smooth` takes them all ([`SettingsArgs`]), `extrema` the
//! selection ([`SelectionArgs`]).

use crate::pipeline::schema::{Group, Kind, Setting, SETTINGS};
use crate::pipeline::SmoothSettings;
use crate::topology::selection::{parse_threshold, DEFAULT_SELECTION};
use crate::topology::Selection;
use crate::Result;
use clap::builder::PossibleValuesParser;
use clap::{Arg, ArgAction, ArgMatches, Command};

/// The flag of one setting.
fn arg_of(s: &Setting) -> Arg {
    let mut help = s.help.to_string();
    if let (Some(default), false) = (s.default, s.kind == Kind::Switch) {
        help.push_str(&format!(" [default: {default}]"));
    }
    let mut arg = Arg::new(s.name).long(s.flag()).help(help);
    arg = match s.kind {
        Kind::Switch => arg.action(ArgAction::SetTrue),
        Kind::Choice(names) => {
            arg.action(ArgAction::Set).value_name(s.value_name).value_parser(PossibleValuesParser::new(names))
        }
        // the library's message for a negative value, not clap's "unexpected argument"
        _ => arg.action(ArgAction::Set).value_name(s.value_name).allow_negative_numbers(true),
    };
    if s.group == Group::Selection {
        let others: Vec<&str> = SETTINGS
            .iter()
            .filter(|o| o.group == Group::Selection && o.name != s.name && Some(o.name) != s.partner)
            .map(|o| o.name)
            .collect();
        arg = arg.conflicts_with_all(others);
        if let Some(p) = s.partner {
            arg = arg.requires(p);
        }
    }
    arg
}

/// The settings of `groups` given on the command line, as `(name, text)`.
fn given(m: &ArgMatches, groups: &[Group]) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    for s in SETTINGS.iter().filter(|s| groups.contains(&s.group)) {
        match s.kind {
            Kind::Switch => {
                if m.try_get_one::<bool>(s.name).ok().flatten().copied().unwrap_or(false) {
                    out.push((s.name, "true".to_string()));
                }
            }
            _ => {
                if let Some(v) = m.try_get_one::<String>(s.name).ok().flatten() {
                    out.push((s.name, v.clone()));
                }
            }
        }
    }
    out
}

fn add(cmd: Command, groups: &[Group]) -> Command {
    SETTINGS.iter().filter(|s| groups.contains(&s.group)).fold(cmd, |cmd, s| cmd.arg(arg_of(s)))
}

const ALL: [Group; 4] = [Group::Selection, Group::Energy, Group::Solver, Group::Run];

/// Every setting of `smooth`, as given.
#[derive(Clone, Debug, Default)]
pub struct SettingsArgs {
    given: Vec<(&'static str, String)>,
}

impl SettingsArgs {
    /// The settings (defaults where not given).
    ///
    /// # Errors
    /// As [`SmoothSettings::from_texts`].
    pub fn settings(&self) -> Result<SmoothSettings> {
        SmoothSettings::from_texts(self.given.iter().map(|(n, v)| (*n, v.as_str())))
    }
}

impl clap::FromArgMatches for SettingsArgs {
    fn from_arg_matches(m: &ArgMatches) -> std::result::Result<Self, clap::Error> {
        Ok(SettingsArgs { given: given(m, &ALL) })
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> std::result::Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl clap::Args for SettingsArgs {
    fn augment_args(cmd: Command) -> Command {
        add(cmd, &ALL)
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        add(cmd, &ALL)
    }
}

/// The selection's settings (`extrema`), as given.
#[derive(Clone, Debug, Default)]
pub struct SelectionArgs {
    given: Vec<(&'static str, String)>,
}

impl SelectionArgs {
    /// The selection ([`DEFAULT_SELECTION`] when no rule is given).
    ///
    /// # Errors
    /// As [`Selection::from_settings`].
    pub fn selection(&self) -> Result<Selection> {
        let given: Vec<(&str, &str)> = self.given.iter().map(|(n, v)| (*n, v.as_str())).collect();
        for (name, text) in &given {
            if let Some(s) = crate::pipeline::schema::find(name) {
                s.kind.check(s.name, text)?;
            }
        }
        match Selection::from_settings(&given)? {
            Some(s) => Ok(s),
            None => parse_threshold(DEFAULT_SELECTION),
        }
    }
}

impl clap::FromArgMatches for SelectionArgs {
    fn from_arg_matches(m: &ArgMatches) -> std::result::Result<Self, clap::Error> {
        Ok(SelectionArgs { given: given(m, &[Group::Selection]) })
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> std::result::Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl clap::Args for SelectionArgs {
    fn augment_args(cmd: Command) -> Command {
        add(cmd, &[Group::Selection])
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        add(cmd, &[Group::Selection])
    }
}
