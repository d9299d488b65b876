//! What a calibration sweeps for a technique. Each setting the technique states it
//! depends on ([`Tunables`]) takes its range, given or default; every other setting
//! keeps the value the settings give it. A range given for a setting the technique
//! ignores, a technique with nothing to sweep, and a sweep of one point are refused,
//! each with a message that says what would be valid.

use gnomon_render::techniques::{TechniqueRegistry, Tunables};
use gnomon_scene::settings::{
    BiasSettings, DEPTH_BIAS_RANGE, KernelUnit, NORMAL_OFFSET_RANGE, PCF_KERNEL_TEXELS_RANGE,
    SLOPE_BIAS_RANGE,
};

use super::sweep::SweepRange;

/// One point of the sweep: the bias, and the PCF kernel's width.
#[derive(Clone, Debug, PartialEq)]
pub struct Tuned {
    pub bias: BiasSettings,
    /// `shadow.filter.pcf_kernel`, in the settings' kernel unit.
    pub pcf_kernel: f32,
}

/// The ranges asked for on the command line; `None` takes the default.
#[derive(Clone, Copy, Debug, Default)]
pub struct Requested {
    pub depth_bias: Option<SweepRange>,
    pub slope_bias: Option<SweepRange>,
    pub normal_offset: Option<SweepRange>,
    pub kernel: Option<SweepRange>,
}

/// The slope-bias values swept when none are given: none to well past the default.
pub const DEFAULT_SLOPE_BIAS: SweepRange = SweepRange { low: 0.0, high: 4.0, steps: 9 };
/// The normal-offset values swept when none are given, in texels.
pub const DEFAULT_NORMAL_OFFSET: SweepRange = SweepRange { low: 0.0, high: 2.0, steps: 9 };
/// The kernel widths swept when none are given (kernels in texels only): 1 to 9.
pub const DEFAULT_KERNEL: SweepRange = SweepRange { low: 1.0, high: 9.0, steps: 5 };

/// Why a calibration was refused before any work.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The technique is not registered.
    #[error(transparent)]
    Unknown(#[from] gnomon_scene::settings::SettingsError),
    #[error(
        "technique `{technique}` has no bias or kernel to sweep: its shadow depends on none of the depth bias, slope bias, normal offset or PCF kernel"
    )]
    NothingTunable { technique: String },
    #[error("technique `{technique}` has no {setting} to sweep ({flag}); techniques with one: {with}")]
    Ignored { technique: String, setting: &'static str, flag: &'static str, with: String },
    #[error("{flag} = {value} is invalid: {valid}")]
    Value { flag: &'static str, value: f32, valid: String },
    #[error(
        "nothing to sweep: every range holds one value; give at least one LOW..HIGH:STEPS with STEPS ≥ 2 (--sweep-depth-bias, --sweep-slope-bias, --sweep-normal-offset or --sweep-kernel)"
    )]
    OnePoint,
    #[error(
        "{flag} {range} gives {distinct} distinct values in {steps} steps: the depth bias is a whole number of \
         units, so give at most {distinct} steps over that range"
    )]
    RepeatedValues { flag: &'static str, range: SweepRange, steps: u32, distinct: usize },
    #[error(
        "the sweep is {points} points ({detail}), each a render of every view: at most {MAX_GRID_POINTS}; sweep \
         fewer settings at once, or fewer steps"
    )]
    TooManyPoints { points: u64, detail: String },
}

/// The most points a calibration's grid may hold: each is a render of every view, so
/// 1024 points at the default 4 views are some 4 096 renders.
pub const MAX_GRID_POINTS: u64 = 1024;

/// One setting a calibration may sweep, as messages name it.
struct Knob {
    setting: &'static str,
    flag: &'static str,
    /// Whether a technique's shadow depends on it.
    moves: fn(&Tunables) -> bool,
    /// Whether a value is within the setting's own range (declared with the setting,
    /// `settings::ranges`).
    valid: fn(f32, KernelUnit) -> bool,
    /// That range, for the message.
    range: fn(KernelUnit) -> String,
}

const DEPTH_BIAS: Knob = Knob {
    setting: "depth bias",
    flag: "--sweep-depth-bias",
    moves: |t| t.raster_bias,
    valid: |v, _| DEPTH_BIAS_RANGE.allows(v),
    range: |_| DEPTH_BIAS_RANGE.describe(),
};
const SLOPE_BIAS: Knob = Knob {
    setting: "slope bias",
    flag: "--sweep-slope-bias",
    moves: |t| t.raster_bias,
    valid: |v, _| SLOPE_BIAS_RANGE.allows(v),
    range: |_| SLOPE_BIAS_RANGE.describe(),
};
const NORMAL_OFFSET: Knob = Knob {
    setting: "normal offset",
    flag: "--sweep-normal-offset",
    moves: |t| t.normal_offset,
    valid: |v, _| NORMAL_OFFSET_RANGE.allows(v),
    range: |_| NORMAL_OFFSET_RANGE.describe(),
};
const KERNEL: Knob = Knob {
    setting: "PCF kernel",
    flag: "--sweep-kernel",
    moves: |t| t.kernel,
    valid: |v, unit| match unit {
        KernelUnit::Texels => PCF_KERNEL_TEXELS_RANGE.allows(v),
        KernelUnit::World => gnomon_scene::limits::LIGHT_RANGE.allows(v),
    },
    range: |unit| match unit {
        KernelUnit::Texels => PCF_KERNEL_TEXELS_RANGE.describe(),
        KernelUnit::World => gnomon_scene::limits::LIGHT_RANGE.valid.into(),
    },
};

/// The values a calibration of `technique` gives `knob`: the range asked for, else
/// its default (if it has one), else the `fixed` value; a range asked for a setting
/// the technique ignores is refused.
struct Values<'a> {
    registry: &'a TechniqueRegistry,
    technique: &'a str,
    tunables: Tunables,
    kernel_unit: KernelUnit,
}

impl Values<'_> {
    fn of(
        &self,
        knob: &Knob,
        asked: Option<SweepRange>,
        default: Option<SweepRange>,
        fixed: f32,
    ) -> Result<Vec<f32>, PlanError> {
        let values = match (asked, (knob.moves)(&self.tunables)) {
            (Some(_), false) => {
                return Err(PlanError::Ignored {
                    technique: self.technique.to_owned(),
                    setting: knob.setting,
                    flag: knob.flag,
                    with: self.registry.names(|t| (knob.moves)(&t.tunables())),
                });
            }
            (Some(r), true) => r.values(),
            (None, true) => default.map_or(vec![fixed], |r| r.values()),
            (None, false) => vec![fixed],
        };
        match values.iter().find(|&&v| !(knob.valid)(v, self.kernel_unit)) {
            Some(&value) => {
                Err(PlanError::Value { flag: knob.flag, value, valid: (knob.range)(self.kernel_unit) })
            }
            None => Ok(values),
        }
    }
}

/// Every combination of the swept values for `technique` (registered in
/// `registry`), around `base`, whose kernel is measured in `kernel_unit`.
pub fn grid(
    requested: &Requested,
    registry: &TechniqueRegistry,
    technique: &gnomon_scene::settings::Technique,
    base: &Tuned,
    kernel_unit: KernelUnit,
) -> Result<Vec<Tuned>, PlanError> {
    let tunables = registry.get(technique)?.tunables();
    let name = technique.to_string();
    if tunables == Tunables::NONE {
        return Err(PlanError::NothingTunable { technique: name });
    }
    let values = Values { registry, technique: &name, tunables, kernel_unit };
    let b = &base.bias;
    let depth_biases = values.of(&DEPTH_BIAS, requested.depth_bias, None, b.depth_bias as f32)?;
    let slope_biases =
        values.of(&SLOPE_BIAS, requested.slope_bias, Some(DEFAULT_SLOPE_BIAS), b.slope_bias)?;
    let normal_offsets =
        values.of(&NORMAL_OFFSET, requested.normal_offset, Some(DEFAULT_NORMAL_OFFSET), b.normal_offset)?;
    let default_kernel = (kernel_unit == KernelUnit::Texels).then_some(DEFAULT_KERNEL);
    let kernels = values.of(&KERNEL, requested.kernel, default_kernel, base.pcf_kernel)?;
    // The depth bias is a whole number: a range of more steps than whole values would
    // measure the same points many times over.
    let mut depth_biases: Vec<f32> = depth_biases.iter().map(|v| v.round()).collect();
    depth_biases.dedup();
    if let Some(range) = requested.depth_bias
        && depth_biases.len() < range.steps as usize
    {
        return Err(PlanError::RepeatedValues {
            flag: DEPTH_BIAS.flag,
            range,
            steps: range.steps,
            distinct: depth_biases.len(),
        });
    }
    let counts = [depth_biases.len(), slope_biases.len(), normal_offsets.len(), kernels.len()];
    let points: u64 = counts.iter().map(|&n| n as u64).product();
    if points > MAX_GRID_POINTS {
        let [d, s, n, k] = counts;
        let detail = format!("{d} depth biases × {s} slope biases × {n} normal offsets × {k} kernels");
        return Err(PlanError::TooManyPoints { points, detail });
    }
    let mut grid = Vec::new();
    for &depth_bias in &depth_biases {
        for &slope_bias in &slope_biases {
            for &normal_offset in &normal_offsets {
                for &pcf_kernel in &kernels {
                    let bias = BiasSettings {
                        depth_bias: depth_bias.round() as i32,
                        slope_bias,
                        normal_offset,
                        ..b.clone()
                    };
                    grid.push(Tuned { bias, pcf_kernel });
                }
            }
        }
    }
    if grid.len() < 2 {
        return Err(PlanError::OnePoint);
    }
    Ok(grid)
}

#[cfg(test)]
mod tests {
    use gnomon_render::techniques::{MapSupport, ShadowTechnique};
    use gnomon_scene::settings::{FilterSettings, Technique};

    use super::*;

    /// A technique whose shadow no setting moves: a test's stand-in for one that
    /// traces rays, say.
    struct Untunable;

    impl ShadowTechnique for Untunable {
        fn technique(&self) -> Technique {
            Technique::named("untunable")
        }
        fn summary(&self) -> &'static str {
            "Fully lit everywhere (a test's technique)."
        }
        fn wgsl(&self) -> &'static [&'static str] {
            &["fn sample_shadow(q: ShadowQuery) -> f32 {\n    return 1.0;\n}\n"]
        }
        fn maps(&self) -> MapSupport {
            MapSupport::ANY
        }
        fn filter_reach_texels(&self, _: &FilterSettings, _: f32) -> f32 {
            0.0
        }
        /// Nothing moves it.
        fn tunables(&self) -> Tunables {
            Tunables::NONE
        }
    }

    fn base() -> Tuned {
        Tuned { bias: BiasSettings::default(), pcf_kernel: 3.0 }
    }

    fn range(s: &str) -> Option<SweepRange> {
        Some(s.parse().unwrap())
    }

    #[test]
    fn each_technique_sweeps_what_moves_its_shadow_and_nothing_else() {
        let registry = TechniqueRegistry::builtin();
        let grid_of = |technique: Technique, requested: Requested| {
            grid(&requested, &registry, &technique, &base(), KernelUnit::Texels)
        };
        // By default: slope bias × normal offset, and the kernel for PCF kernels.
        let hard = grid_of(Technique::HARD, Requested::default()).unwrap();
        assert_eq!(hard.len(), 9 * 9);
        assert!(hard.iter().all(|t| t.pcf_kernel == 3.0 && t.bias.depth_bias == 0));
        let pcf = grid_of(Technique::PCF, Requested::default()).unwrap();
        assert_eq!(pcf.len(), 9 * 9 * 5);
        let kernels: std::collections::BTreeSet<u32> = pcf.iter().map(|t| t.pcf_kernel as u32).collect();
        assert_eq!(kernels.into_iter().collect::<Vec<_>>(), [1, 3, 5, 7, 9]);
        // Only the kernel.
        let only_kernel = Requested {
            slope_bias: range("1.5..1.5:1"),
            normal_offset: range("0.6..0.6:1"),
            kernel: range("3..7:3"),
            ..Default::default()
        };
        assert_eq!(grid_of(Technique::PCF_TENT, only_kernel).unwrap().len(), 3);
        // A kernel for a technique without one names those that have one.
        let err = grid_of(Technique::PCF2X2, Requested { kernel: range("3..7:3"), ..Default::default() });
        assert_eq!(
            err.unwrap_err().to_string(),
            "technique `pcf2x2` has no PCF kernel to sweep (--sweep-kernel); techniques with one: pcf, pcf-tent or pcf-poisson"
        );
        // Out-of-range values and a single point.
        let wide = Requested { kernel: range("1..40:4"), ..Default::default() };
        assert!(matches!(
            grid_of(Technique::PCF, wide),
            Err(PlanError::Value { flag: "--sweep-kernel", .. })
        ));
        let negative = Requested { slope_bias: range("-1..1:3"), ..Default::default() };
        assert!(matches!(grid_of(Technique::HARD, negative), Err(PlanError::Value { .. })));
        let one =
            Requested { slope_bias: range("1..1:1"), normal_offset: range("0..0:1"), ..Default::default() };
        assert!(matches!(grid_of(Technique::HARD, one), Err(PlanError::OnePoint)));
    }

    /// The audit's two: 64 steps of a whole-number bias over 0..1 (two values), and a
    /// grid of 64⁴ points.
    #[test]
    fn repeated_points_and_huge_grids_are_refused() {
        let grid_of = |requested: Requested| {
            grid(&requested, &TechniqueRegistry::builtin(), &Technique::HARD, &base(), KernelUnit::Texels)
        };
        let repeated = grid_of(Requested { depth_bias: range("0..1:64"), ..Default::default() }).unwrap_err();
        assert!(matches!(repeated, PlanError::RepeatedValues { distinct: 2, steps: 64, .. }), "{repeated}");
        let whole = Requested {
            depth_bias: range("0..63:64"),
            slope_bias: range("0..0:1"),
            normal_offset: range("0..0:1"),
            kernel: None,
        };
        assert_eq!(grid_of(whole).unwrap().len(), 64, "64 whole values in 0..63");
        let all = Requested {
            depth_bias: range("0..63:64"),
            slope_bias: range("0..4:64"),
            normal_offset: range("0..2:64"),
            kernel: None,
        };
        let huge = grid_of(all).unwrap_err();
        assert!(matches!(huge, PlanError::TooManyPoints { points: 262_144, .. }), "{huge}");
    }

    #[test]
    fn a_technique_with_nothing_to_sweep_is_refused() {
        let registry = TechniqueRegistry::builtin().with(&Untunable).unwrap();
        let err = grid(
            &Requested::default(),
            &registry,
            &Technique::named("untunable"),
            &base(),
            KernelUnit::Texels,
        )
        .unwrap_err();
        assert!(matches!(&err, PlanError::NothingTunable { technique } if technique == "untunable"));
        assert!(err.to_string().contains("has no bias or kernel to sweep"), "{err}");
    }
}
