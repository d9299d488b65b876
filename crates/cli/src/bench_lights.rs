//! The paths `gnomon bench` moves a light along every frame (`--sun-path`,
//! `--spot-path`, `--point-path`), so that no kept map is valid: what a moving light
//! costs.

use clap::ValueEnum;
use glam::Vec3;
use gnomon_math::solar::DayArc;
use gnomon_scene::{Light, Settings};

/// How `--sun-path` moves the sun.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SunPathKind {
    /// A day's arc ([`DayArc::EQUINOX_45_NORTH`]).
    Day,
}

impl SunPathKind {
    fn arc(self) -> DayArc {
        match self {
            SunPathKind::Day => DayArc::EQUINOX_45_NORTH,
        }
    }
}

/// How `--spot-path` moves the spot.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SpotPathKind {
    /// Its aim swung 30° across, about the vertical through it, from 15° one side
    /// of the scene's aim to 15° the other.
    Sweep,
}

impl SpotPathKind {
    /// The point frame `fraction` of the path (0 to 1) aims the spot at, for a spot
    /// at `position` that the scene aims along `direction`.
    fn target(self, position: Vec3, direction: Vec3, fraction: f32) -> Vec3 {
        match self {
            SpotPathKind::Sweep => {
                let angle = (fraction - 0.5) * 30f32.to_radians();
                position + glam::Quat::from_rotation_y(angle) * direction
            }
        }
    }
}

/// How `--point-path` moves the point light.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PointPathKind {
    /// Carried along world x across a twentieth of its range, centred on its place
    /// in the scene.
    Sway,
}

impl PointPathKind {
    /// Where frame `fraction` of the path (0 to 1) puts a point light that the scene
    /// puts at `position`, with range `range`.
    fn position(self, position: Vec3, range: f32, fraction: f32) -> Vec3 {
        match self {
            PointPathKind::Sway => position + Vec3::X * (fraction - 0.5) * range / 20.0,
        }
    }
}

/// The paths the flags ask for.
#[derive(Clone, Copy, Debug)]
pub struct LightPathArgs {
    /// `--sun-path`.
    pub sun: Option<SunPathKind>,
    /// `--spot-path`.
    pub spot: Option<SpotPathKind>,
    /// `--point-path`.
    pub point: Option<PointPathKind>,
}

/// A spot's path from where the scene aims it.
#[derive(Clone, Copy, Debug)]
struct SpotPath {
    kind: SpotPathKind,
    position: Vec3,
    direction: Vec3,
}

/// A point light's path from where the scene puts it.
#[derive(Clone, Copy, Debug)]
struct PointPath {
    kind: PointPathKind,
    position: Vec3,
    range: f32,
}

/// The light paths of a bench run, from the scene's first light (the one a path
/// moves; `check_args` refuses a path for another kind of light).
#[derive(Clone, Copy, Debug)]
pub struct LightPaths {
    sun: Option<DayArc>,
    spot: Option<SpotPath>,
    point: Option<PointPath>,
}

impl LightPaths {
    /// The paths `args` ask for, of the scene's first light `first`.
    pub fn new(args: LightPathArgs, first: Option<Light>) -> LightPaths {
        let spot = match (args.spot, first) {
            (Some(kind), Some(Light::Spot(spot))) => {
                Some(SpotPath { kind, position: spot.position, direction: spot.direction })
            }
            (Some(_), Some(Light::Directional(_) | Light::Point(_)) | None) | (None, _) => None,
        };
        let point = match (args.point, first) {
            (Some(kind), Some(Light::Point(point))) => {
                Some(PointPath { kind, position: point.position, range: point.range })
            }
            (Some(_), Some(Light::Directional(_) | Light::Spot(_)) | None) | (None, _) => None,
        };
        LightPaths { sun: args.sun.map(SunPathKind::arc), spot, point }
    }

    /// Puts the light where frame `fraction` of its path (0 to 1) has it.
    pub fn place(&self, settings: &mut Settings, fraction: f32) {
        if let Some(arc) = self.sun {
            let sun = arc.at(fraction);
            settings.light.sun_elevation = Some(sun.elevation);
            settings.light.sun_azimuth = Some(sun.azimuth);
        }
        if let Some(SpotPath { kind, position, direction }) = self.spot {
            settings.light.spot_target = Some(kind.target(position, direction, fraction));
        }
        if let Some(PointPath { kind, position, range }) = self.point {
            settings.light.point_position = Some(kind.position(position, range, fraction));
        }
    }
}
