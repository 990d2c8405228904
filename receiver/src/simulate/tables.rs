//! The scenario's sensor tables (`[ins]`, `[dr]`, `[accel]`): parsed and checked before
//! anything is simulated, errors naming the bad key.

use super::SimulateError;
use gpsrx_ins_aiding::{AccelSensorConfig, DrSensorConfig, InsErrorConfig};
use gpsrx_samples::sim::Scenario;

/// Parses and checks a scenario's `[ins]` table (None without one). Errors name the bad key:
/// an unknown key, a value of the wrong type, or a value out of range.
pub fn ins_config(scenario: &Scenario) -> Result<Option<InsErrorConfig>, SimulateError> {
    let Some(cfg) = parse_sensor_table::<InsErrorConfig>("ins", scenario.ins.as_ref())? else {
        return Ok(None);
    };
    cfg.validate().map_err(|e| SimulateError::SensorModel {
        table: "ins",
        source: Box::new(e),
    })?;
    Ok(Some(cfg))
}

/// Parses and checks a scenario's `[dr]` table (None without one).
pub fn dr_config(scenario: &Scenario) -> Result<Option<DrSensorConfig>, SimulateError> {
    let Some(cfg) = parse_sensor_table::<DrSensorConfig>("dr", scenario.dr.as_ref())? else {
        return Ok(None);
    };
    cfg.validate().map_err(|e| SimulateError::SensorModel {
        table: "dr",
        source: Box::new(e),
    })?;
    Ok(Some(cfg))
}

/// Parses and checks a scenario's `[accel]` table (None without one).
pub fn accel_config(scenario: &Scenario) -> Result<Option<AccelSensorConfig>, SimulateError> {
    let Some(cfg) = parse_sensor_table::<AccelSensorConfig>("accel", scenario.accel.as_ref())?
    else {
        return Ok(None);
    };
    cfg.validate().map_err(|e| SimulateError::SensorModel {
        table: "accel",
        source: Box::new(e),
    })?;
    Ok(Some(cfg))
}

/// Deserialises a sensor table whose every key has a default. Each key alone is then a valid
/// table, so parsing them one by one finds the key a type error belongs to.
fn parse_sensor_table<T: serde::de::DeserializeOwned>(
    table_name: &'static str,
    table: Option<&toml::Table>,
) -> Result<Option<T>, SimulateError> {
    let Some(table) = table else {
        return Ok(None);
    };
    let parse = |t: toml::Table| -> Result<T, toml::de::Error> { toml::Value::Table(t).try_into() };
    for (key, value) in table {
        let mut one = toml::Table::new();
        one.insert(key.clone(), value.clone());
        if let Err(e) = parse(one) {
            return Err(SimulateError::SensorTable {
                table: table_name,
                key: Some(key.clone()),
                message: e.message().trim().to_string(),
            });
        }
    }
    let cfg = parse(table.clone()).map_err(|e| SimulateError::SensorTable {
        table: table_name,
        key: None,
        message: e.message().trim().to_string(),
    })?;
    Ok(Some(cfg))
}
