//! Receiver options given by name (a manifest's columns, Python keyword arguments) applied to a
//! [`ReceiverConfig`].
//!
//! A plain key is a field of the `[run]` table ([`crate::config::RunSettings`]: `rate_hz`,
//! `tropo`, `elevation_mask_deg`, `approx_llh`, ...); a dotted key `table.field` names another
//! table (`tracking.cn0_lost_dbhz`, `dr.filter`); the plain key `tracking` is
//! `tracking.mode` (`tracking = "vector"`). Values are TOML values. Unknown keys and
//! values of the wrong type are errors that list the valid keys (serde `deny_unknown_fields`),
//! and the result is validated as a `gpsrx.toml` file is.

use crate::config::{ConfigError, ReceiverConfig};

/// Where the options came from, in error messages.
pub const OPTIONS_SOURCE: &str = "options";

/// The configuration of `base` (the text of a `gpsrx.toml` file, or empty) with `options` set
/// over it, validated.
pub fn config_with_options(
    base: Option<(&str, &str)>,
    options: &toml::Table,
) -> Result<ReceiverConfig, ConfigError> {
    let mut table = match base {
        Some((text, path)) => {
            toml::from_str::<toml::Table>(text).map_err(|e| ConfigError::Parse {
                path: path.to_string(),
                message: e.to_string(),
            })?
        }
        None => toml::Table::new(),
    };
    for (key, value) in options {
        let path: Vec<&str> = if key.contains('.') {
            key.split('.').collect()
        } else if key == "tracking" {
            // `tracking="vector"` (a Python keyword, a manifest column): `[tracking] mode`.
            vec!["tracking", "mode"]
        } else {
            vec!["run", key.as_str()]
        };
        set_path(&mut table, key, &path, value.clone())?;
    }
    let source = base.map_or(OPTIONS_SOURCE, |(_, p)| p);
    let config: ReceiverConfig =
        toml::Value::Table(table)
            .try_into()
            .map_err(|e: toml::de::Error| ConfigError::Parse {
                path: source.to_string(),
                message: format!(
                    "{} (plain option names are [run] settings, e.g. rate_hz, tropo; `tracking.NAME` sets a [tracking] value)",
                    e.message().trim()
                ),
            })?;
    config.validate()?;
    Ok(config)
}

/// Sets `table.path[0].path[1]...` to `value`, making the tables on the way.
fn set_path(
    table: &mut toml::Table,
    key: &str,
    path: &[&str],
    value: toml::Value,
) -> Result<(), ConfigError> {
    let Some((last, parents)) = path.split_last() else {
        return Ok(());
    };
    let mut t = table;
    for section in parents {
        let entry = t
            .entry(section.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let toml::Value::Table(inner) = entry else {
            return Err(ConfigError::Invalid(format!(
                "option `{key}`: `{section}` is a value, not a table of the configuration (tables: run, tracking, dr)"
            )));
        };
        t = inner;
    }
    t.insert(last.to_string(), value);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TropoModel;

    fn table(text: &str) -> toml::Table {
        toml::from_str(text).expect("test table")
    }

    #[test]
    fn plain_keys_set_run_and_dotted_keys_other_tables() {
        let c = config_with_options(
            None,
            &table("rate_hz = 2\ntropo = \"none\"\n\"tracking.cn0_lost_dbhz\" = 30"),
        )
        .expect("valid options");
        assert_eq!(c.run.rate_hz, 2.0);
        assert_eq!(c.run.tropo, TropoModel::None);
        assert_eq!(c.tracking.cn0_lost_dbhz, 30.0);
        // Plots are on unless an option (a manifest column, a Python keyword) says no.
        assert!(c.run.plots);
        let off = config_with_options(None, &table("plots = false")).expect("valid options");
        assert!(!off.run.plots);
        // Everything else keeps its default.
        assert_eq!(
            c.run.elevation_mask_deg,
            ReceiverConfig::default().run.elevation_mask_deg
        );
    }

    #[test]
    fn options_override_the_file() {
        let c = config_with_options(
            Some(("[run]\nrate_hz = 5\nelevation_mask_deg = 10", "gpsrx.toml")),
            &table("rate_hz = 1"),
        )
        .expect("valid");
        assert_eq!((c.run.rate_hz, c.run.elevation_mask_deg), (1.0, 10.0));
    }

    #[test]
    fn unknown_keys_and_bad_values_are_named() {
        let e = config_with_options(None, &table("rate_hzz = 1")).expect_err("unknown key");
        assert!(e.to_string().contains("rate_hzz"), "{e}");
        let e = config_with_options(None, &table("rate_hz = 500")).expect_err("out of range");
        assert!(e.to_string().contains("rate 500 Hz: use 1 to 50 Hz"), "{e}");
    }
}
