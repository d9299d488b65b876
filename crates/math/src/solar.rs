//! The sun's place in the sky at a time of day: the viewer's time-of-day control.
//!
//! Standard spherical astronomy (e.g. Duffie & Beckman, "Solar Engineering of Thermal
//! Processes", §1.6): with latitude φ, declination δ and hour angle H = 15° (t − 12 h)
//! in local solar time,
//!
//! sin(elevation) = sin φ sin δ + cos φ cos δ cos H,
//! azimuth = atan2(−sin H, tan δ cos φ − sin φ cos H), from north toward east.
//!
//! Gnomon's scenes put north at +z and east at +x, so this azimuth is the one
//! `--sun-azimuth` takes (measured from +z toward +x).

/// The sun's declination in degrees on `day_of_year` (1 = 1 January), by Cooper's
/// approximation δ = −23.44° cos(360° (N + 10) / 365).
pub fn declination_degrees(day_of_year: f32) -> f32 {
    -23.44 * (360.0 / 365.0 * (day_of_year + 10.0)).to_radians().cos()
}

/// Where the sun stands in the sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunPosition {
    /// Degrees above the horizon (negative below it).
    pub elevation: f32,
    /// Degrees from north (+z) toward east (+x), in [0, 360).
    pub azimuth: f32,
}

/// The sun at `hour` of local solar time (12 is noon) at `latitude` degrees (north
/// positive) with the given declination.
pub fn sun_position(hour: f32, latitude: f32, declination: f32) -> SunPosition {
    let (phi, delta) = (latitude.to_radians(), declination.to_radians());
    let h = (15.0 * (hour - 12.0)).to_radians();
    let sin_elevation = phi.sin() * delta.sin() + phi.cos() * delta.cos() * h.cos();
    let elevation = sin_elevation.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = (-h.sin()).atan2(delta.tan() * phi.cos() - phi.sin() * h.cos()).to_degrees();
    SunPosition { elevation, azimuth: azimuth.rem_euclid(360.0) }
}

/// A day's arc of the sun, for what must follow a sun that moves every frame (`gnomon
/// bench --sun-path day`): at 45° N on an equinox, from 7 h to 17 h of solar time.
/// The sun stays 10.5° or more above the horizon, so every shadow stays in the scene,
/// and each step of a bench's frames turns it by a fraction of a degree, so that no
/// kept map is ever valid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DayArc {
    /// Degrees north (positive) or south.
    pub latitude: f32,
    /// The sun's declination in degrees (0 on an equinox).
    pub declination: f32,
    /// Local solar hour at the start of the arc.
    pub first_hour: f32,
    /// Local solar hour at its end.
    pub last_hour: f32,
}

impl DayArc {
    /// The arc `bench --sun-path day` follows.
    pub const EQUINOX_45_NORTH: DayArc =
        DayArc { latitude: 45.0, declination: 0.0, first_hour: 7.0, last_hour: 17.0 };

    /// The sun `fraction` of the way along the arc (0 its start, 1 its end).
    pub fn at(&self, fraction: f32) -> SunPosition {
        let hour = self.first_hour + fraction.clamp(0.0, 1.0) * (self.last_hour - self.first_hour);
        sun_position(hour, self.latitude, self.declination)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equinox_noon_stands_due_south_at_the_colatitude() {
        for latitude in [10.0f32, 45.0, 60.0] {
            let sun = sun_position(12.0, latitude, 0.0);
            assert!((sun.elevation - (90.0 - latitude)).abs() < 1e-3, "{sun:?}");
            assert!((sun.azimuth - 180.0).abs() < 1e-3, "{sun:?}");
        }
    }

    #[test]
    fn equinox_sun_rises_due_east_at_six_and_sets_due_west_at_eighteen() {
        let rise = sun_position(6.0, 45.0, 0.0);
        assert!(rise.elevation.abs() < 1e-3 && (rise.azimuth - 90.0).abs() < 1e-3, "{rise:?}");
        let set = sun_position(18.0, 45.0, 0.0);
        assert!(set.elevation.abs() < 1e-3 && (set.azimuth - 270.0).abs() < 1e-3, "{set:?}");
    }

    #[test]
    fn summer_days_are_longer_and_the_sun_climbs_higher() {
        let june = declination_degrees(172.0);
        assert!((june - 23.44).abs() < 0.1, "{june}");
        assert!(declination_degrees(355.0) < -23.0);
        // At 45° N the midsummer sun is up at 5:00 and stands 68.4° high at noon.
        assert!(sun_position(5.0, 45.0, june).elevation > 0.0);
        assert!((sun_position(12.0, 45.0, june).elevation - 68.44).abs() < 0.1);
        // The morning and the afternoon mirror each other about the meridian.
        let (am, pm) = (sun_position(9.0, 45.0, june), sun_position(15.0, 45.0, june));
        assert!((am.elevation - pm.elevation).abs() < 1e-3);
        assert!((am.azimuth + pm.azimuth - 360.0).abs() < 1e-3);
    }

    #[test]
    fn the_day_arc_stays_up_and_turns_from_east_to_west() {
        let arc = DayArc::EQUINOX_45_NORTH;
        let steps = 200;
        let mut previous = arc.at(0.0);
        assert!((previous.elevation - 10.5).abs() < 0.1, "{previous:?}");
        for k in 1..=steps {
            let sun = arc.at(k as f32 / steps as f32);
            assert!(sun.elevation >= 10.4, "{sun:?}");
            // Azimuth grows through south (180°) all day; every step moves the sun.
            assert!(sun.azimuth > previous.azimuth, "{previous:?} then {sun:?}");
            previous = sun;
        }
        let noon = arc.at(0.5);
        assert!((noon.elevation - 45.0).abs() < 1e-3 && (noon.azimuth - 180.0).abs() < 1e-3);
    }
}
