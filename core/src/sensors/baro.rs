//! Barometer: pressure and temperature of the International Standard Atmosphere (troposphere,
//! below 11 km) at the vehicle's altitude above mean sea level, plus white pressure noise; the
//! pressure altitude is what the ISA says the measured pressure means.

/// Sea-level pressure of the ISA, Pa.
pub const SEA_LEVEL_PRESSURE: f64 = 101_325.0;
/// Sea-level temperature of the ISA, K.
pub const SEA_LEVEL_TEMPERATURE: f64 = 288.15;
/// Temperature lapse rate of the ISA troposphere, K/m.
pub const LAPSE_RATE: f64 = 0.0065;
/// Exponent g·M/(R·L) of the barometric formula (g = 9.80665, M = 0.0289644, R = 8.31432).
pub const BAROMETRIC_EXPONENT: f64 = 5.255_877;
/// 0 °C in kelvin.
pub const ZERO_CELSIUS: f64 = 273.15;

/// One barometer sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaroReading {
    /// Static pressure, hPa.
    pub pressure_hpa: f64,
    /// Air temperature, °C.
    pub temperature_c: f64,
    /// Altitude above mean sea level the measured pressure stands for in the ISA, m.
    pub pressure_altitude: f64,
}

/// ISA temperature at `altitude` m above mean sea level, K.
pub fn isa_temperature(altitude: f64) -> f64 {
    SEA_LEVEL_TEMPERATURE - LAPSE_RATE * altitude
}

/// ISA pressure at `altitude` m above mean sea level, Pa: p₀(1 − L·h/T₀)^(gM/RL).
pub fn isa_pressure(altitude: f64) -> f64 {
    SEA_LEVEL_PRESSURE
        * (1.0 - LAPSE_RATE * altitude / SEA_LEVEL_TEMPERATURE).powf(BAROMETRIC_EXPONENT)
}

/// ISA altitude of pressure `pressure` Pa, m (inverse of [`isa_pressure`]).
pub fn isa_altitude(pressure: f64) -> f64 {
    SEA_LEVEL_TEMPERATURE / LAPSE_RATE
        * (1.0 - (pressure / SEA_LEVEL_PRESSURE).powf(1.0 / BAROMETRIC_EXPONENT))
}

/// A reading at `altitude` m MSL with pressure noise `noise_pa` (already drawn), Pa.
pub fn reading(altitude: f64, noise_pa: f64) -> BaroReading {
    let pressure = isa_pressure(altitude) + noise_pa;
    BaroReading {
        pressure_hpa: pressure / 100.0,
        temperature_c: isa_temperature(altitude) - ZERO_CELSIUS,
        pressure_altitude: isa_altitude(pressure),
    }
}
