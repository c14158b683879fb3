//! A small argument parser: positionals and `--key value` options, with
//! errors for unknown or repeated options.

use crate::error::{Error, Result};
use std::collections::BTreeMap;
use std::str::FromStr;

/// Parsed arguments; options are taken one by one, `finish` rejects leftovers.
pub struct Args {
    positionals: Vec<String>,
    options: BTreeMap<String, Option<String>>,
}

/// Options that take no value.
const FLAGS: &[&str] = &["no-expansion"];

impl Args {
    /// Split `argv` into positionals and options.
    pub fn parse(argv: &[String]) -> Result<Self> {
        let mut positionals = Vec::new();
        let mut options = BTreeMap::new();
        let mut it = argv.iter();
        while let Some(a) = it.next() {
            if let Some(key) = a.strip_prefix("--") {
                let value = if FLAGS.contains(&key) {
                    None
                } else {
                    Some(
                        it.next()
                            .ok_or_else(|| Error::Invalid(format!("option --{key} needs a value")))?
                            .clone(),
                    )
                };
                if options.insert(key.to_string(), value).is_some() {
                    return Err(Error::Invalid(format!("option --{key} given twice")));
                }
            } else {
                positionals.push(a.clone());
            }
        }
        Ok(Args {
            positionals,
            options,
        })
    }

    /// The `i`-th positional, or an error naming it.
    pub fn positional(&self, i: usize, name: &str) -> Result<String> {
        self.positionals
            .get(i)
            .cloned()
            .ok_or_else(|| Error::Invalid(format!("missing argument {name}")))
    }

    /// Take an option's value.
    pub fn take(&mut self, key: &str) -> Option<String> {
        self.options.remove(key).flatten()
    }

    /// Take a flag.
    pub fn flag(&mut self, key: &str) -> bool {
        self.options.remove(key).is_some()
    }

    /// Take and parse an option's value.
    pub fn take_parsed<T: FromStr>(&mut self, key: &str) -> Result<Option<T>> {
        match self.take(key) {
            None => Ok(None),
            Some(v) => v.parse::<T>().map(Some).map_err(|_| Error::BadOption {
                key: key.into(),
                reason: format!("cannot parse '{v}'"),
            }),
        }
    }

    /// Error on options nobody took, and on extra positionals beyond `n`.
    pub fn finish(&self) -> Result<()> {
        if let Some(k) = self.options.keys().next() {
            return Err(Error::Invalid(format!("unknown option --{k}")));
        }
        Ok(())
    }
}
