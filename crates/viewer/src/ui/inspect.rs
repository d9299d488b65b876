//! The inspection panel: the light's sliders, the debug views, the GPU timings table
//! and the buttons that reproduce a view.

use egui::RichText;
use glam::Vec3;
use gnomon_render::PassTimings;
use gnomon_scene::{Light, lights::Origin, settings::DebugView};

use super::{Images, Model, vec3_drag};
use crate::{Action, View};

impl Model {
    /// The light, the debug views, the GPU timings and the reproduction buttons.
    pub(super) fn inspect_panel(&mut self, ui: &mut egui::Ui, images: &Images) {
        ui.heading("Light");
        self.light_section(ui);
        ui.separator();
        ui.heading("Debug views");
        self.debug_views_section(ui, images);
        ui.separator();
        ui.heading("GPU time");
        self.timings_table(ui);
        ui.separator();
        ui.heading("Reproduce");
        self.reproduce_section(ui);
    }

    /// The light's sliders, and for a sun its time of day, latitude and season.
    fn light_section(&mut self, ui: &mut egui::Ui) {
        let light = self.settings.resolve_light(&self.scene).ok();
        self.light_sliders(ui, light);
        if matches!(light, Some(Light::Directional(_))) {
            let mut t = self.time_of_day;
            let mut changed = false;
            changed |= ui
                .add(egui::Slider::new(&mut t.hour, 4.0..=20.0).text("time of day (h)"))
                .on_hover_text("Local solar time; the sun follows its path across the sky.")
                .changed();
            changed |= ui
                .add(egui::Slider::new(&mut t.latitude, -66.0..=66.0).text("latitude (°)"))
                .on_hover_text("North positive. Scenes put north at +z and east at +x.")
                .changed();
            changed |= ui
                .add(egui::Slider::new(&mut t.day, 1.0..=365.0).text("day of year"))
                .on_hover_text("Sets the sun's declination: 172 is midsummer in the north.")
                .changed();
            self.time_of_day = t;
            if changed {
                self.place_sun();
            }
        }
        ui.label(
            "Right-drag in the view to move the light; the Light section of the settings sets it exactly.",
        );
    }

    /// The lit, texel-density and error views, the tints, the shadow maps and the
    /// comparison with the reference.
    fn debug_views_section(&mut self, ui: &mut egui::Ui, images: &Images) {
        let mut view = self.view;
        ui.horizontal(|ui| {
            ui.selectable_value(&mut view, View::Lit, "lit")
                .on_hover_text("The lit image. Settings › Image › debug-view cascades tints it by cascade.");
            ui.selectable_value(&mut view, View::TexelDensity, "texel density").on_hover_text(
                "Lloyd's m: how many screen pixels one shadow texel spans, blue (1/16) to green (1) to red (16).",
            );
            ui.selectable_value(&mut view, View::Error, "error").on_hover_text(
                "The shadow factor against the ray-traced reference for this view (Compare to compute it).",
            );
        });
        if view != self.view {
            self.pending.push(Action::Show(view));
        }
        // The tints are values of one setting: ticking one unticks the others.
        for (view, value, label, help) in [
            (DebugView::Cascades, "cascades", "cascade colours", "--debug-view cascades"),
            (
                DebugView::Traced,
                "traced",
                "traced pixels",
                "--debug-view traced: magenta where rays decided the shadow (--refine)",
            ),
            (
                DebugView::Pages,
                "pages",
                "virtual pages",
                "--debug-view pages: a virtual map's levels, page borders, pages drawn this frame \
                 (lighter) and fallbacks (red)",
            ),
        ] {
            let mut tint = self.settings.image.debug_view == view;
            if ui.checkbox(&mut tint, label).on_hover_text(help).changed() {
                self.pending.push(Action::Set {
                    id: "debug_view".into(),
                    value: Some(if tint { value } else { "none" }.into()),
                });
            }
        }
        ui.checkbox(&mut self.show_maps, "shadow maps").on_hover_text(
            "The reported light's depth map, every cascade (or cube face) side by side; near is black.",
        );
        if self.show_maps
            && let Some((id, [w, h])) = images.maps
        {
            let width = ui.available_width();
            ui.image((id, egui::vec2(width, width * h as f32 / w as f32)));
        }
        match &self.error_job {
            Some(job) => {
                ui.add(
                    egui::ProgressBar::new(job.progress()).show_percentage().text("tracing the reference"),
                );
            }
            None => {
                if ui
                    .button("Compare with the reference")
                    .on_hover_text(
                        "Ray-trace the ground truth for this view and show where the shadows are wrong.",
                    )
                    .clicked()
                {
                    self.pending.push(Action::CompareWithReference);
                }
            }
        }
        if let Some(error) = &self.error {
            let stale = error.settings != self.frame_settings();
            ui.label(&error.summary);
            if stale {
                ui.label(RichText::new("(for an earlier view)").weak());
            }
        }
    }

    /// The buttons that reproduce this view: as a command, or as a scene file.
    fn reproduce_section(&mut self, ui: &mut egui::Ui) {
        if ui
            .button("Copy as CLI command")
            .on_hover_text("A `gnomon render` command for this view.")
            .clicked()
        {
            self.pending.push(Action::CopyCommand);
        }
        ui.horizontal(|ui| {
            ui.text_edit_singleline(&mut self.save_path);
            if ui
                .button("Save as scene file")
                .on_hover_text("The scene, the camera and every setting.")
                .clicked()
            {
                self.pending.push(Action::SaveSceneFile(self.save_path.clone().into()));
            }
        });
    }

    /// Sliders for the light: a sun's elevation and azimuth, or a spot or point
    /// light's position; each sends its setting's flag.
    fn light_sliders(&mut self, ui: &mut egui::Ui, light: Option<Light>) {
        let xyz = |p: Vec3| format!("{},{},{}", p.x, p.y, p.z);
        let Some(light) = light else { return };
        // By where the light is, as `drag_light`: each kind's settings are named after it.
        let kind = light.type_name();
        match light.emission().origin {
            Origin::Infinite { travel } => {
                let to_light = -travel;
                let mut elevation = to_light.y.clamp(-1.0, 1.0).asin().to_degrees();
                let mut azimuth = to_light.x.atan2(to_light.z).to_degrees().rem_euclid(360.0);
                let label = format!("{kind} elevation (°)");
                if ui.add(egui::Slider::new(&mut elevation, 1.0..=90.0).text(label)).changed() {
                    let id = format!("{kind}_elevation");
                    self.pending.push(Action::Set { id, value: Some(elevation.to_string()) });
                }
                if ui
                    .add(egui::Slider::new(&mut azimuth, 0.0..=360.0).text(format!("{kind} azimuth (°)")))
                    .changed()
                {
                    let id = format!("{kind}_azimuth");
                    self.pending.push(Action::Set { id, value: Some(azimuth.to_string()) });
                }
            }
            Origin::Local { mut position, .. } => {
                if vec3_drag(ui, &format!("{kind} position"), &mut position, self.rig.distance()) {
                    let id = format!("{kind}_position");
                    self.pending.push(Action::Set { id, value: Some(xyz(position)) });
                }
            }
        }
    }

    fn timings_table(&self, ui: &mut egui::Ui) {
        let Some(last) = self.timings.back() else {
            ui.label("This device has no timestamp queries.");
            return;
        };
        let n = self.timings.len() as f64;
        let mean = |f: fn(&PassTimings) -> Option<f64>| -> Option<f64> {
            let values: Vec<f64> = self.timings.iter().filter_map(f).collect();
            (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
        };
        egui::Grid::new("timings").num_columns(2).striped(true).show(ui, |ui| {
            let rows: [(&str, Option<f64>); 6] = [
                ("shadow maps", mean(|t| Some(t.shadow_ms))),
                ("moment filtering", mean(|t| t.filter_ms)),
                ("depth prepass", mean(|t| t.prepass_ms)),
                ("shadow mask", mean(|t| t.mask_ms)),
                ("lighting", mean(|t| Some(t.lighting_ms))),
                ("frame", mean(|t| Some(t.frame_ms))),
            ];
            for (name, ms) in rows {
                if let Some(ms) = ms {
                    ui.label(name);
                    ui.label(format!("{ms:.2} ms"));
                    ui.end_row();
                }
            }
        });
        ui.label(
            RichText::new(format!("mean of the last {n} frames; last frame {:.2} ms", last.frame_ms)).weak(),
        );
        if self.lights.len() > 1 {
            for light in &self.lights {
                ui.label(format!(
                    "{} ({}, {}): shadow {:.2} ms, lighting {:.2} ms",
                    light.name,
                    light.kind,
                    light.technique.name(),
                    light.shadow_ms.unwrap_or(f64::NAN),
                    light.lighting_ms.unwrap_or(f64::NAN)
                ));
            }
        }
    }
}
