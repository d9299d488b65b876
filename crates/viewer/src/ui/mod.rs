//! The viewer's panels, drawn with egui: the settings panel generated from
//! [`SettingsForm`], the light and time-of-day controls, the debug views, GPU timings
//! and the buttons that reproduce a view. Everything they change is sent as an
//! [`Action`]; nothing here touches the GPU. The inspection panel (light, debug
//! views, timings) lives in [`inspect`].

mod inspect;

use std::{
    collections::{BTreeMap, VecDeque},
    sync::Arc,
};

use egui::{Color32, RichText};
use glam::Vec3;
use gnomon_math::solar;
use gnomon_render::{LightStats, PassTimings};
use gnomon_scene::{Scene, Settings, lights::Origin};

use crate::{
    Action, View,
    camera_rig::{CameraMode, CameraRig},
    debug_views::{ErrorJob, Picture},
    reproduce::SceneSource,
    settings_form::{FieldKind, SettingsForm},
};

/// Frames of GPU timings averaged in the timings table.
const TIMING_WINDOW: usize = 30;

/// The state behind the panels: the settings and everything the user chose.
pub(crate) struct Model {
    pub form: SettingsForm,
    pub settings: Settings,
    pub baseline: Settings,
    pub source: SceneSource,
    /// Shared with the frame being rendered (a browser renders while the panels
    /// run); a change copies it only if that frame still holds it.
    pub scene: Arc<Scene>,
    pub rig: CameraRig,
    pub view: View,
    pub show_panel: bool,
    pub show_maps: bool,
    /// Status lines, newest last.
    pub messages: Vec<String>,
    /// Text being typed into the text fields, by field id, until Enter.
    drafts: BTreeMap<String, String>,
    /// GPU timings of the last frames, and the last frame's lights.
    pub timings: VecDeque<PassTimings>,
    pub lights: Vec<LightStats>,
    /// Size of the central view in physical pixels: the render's size.
    pub view_size: [u32; 2],
    /// Where the central view sits in the window: x, y, width, height in physical pixels.
    pub view_rect: [u32; 4],
    pub save_path: String,
    pub time_of_day: TimeOfDay,
    pub density: Option<Picture>,
    pub error_job: Option<ErrorJob>,
    pub error: Option<Picture>,
    /// Actions the panels sent this frame, for the window to carry out.
    pub pending: Vec<Action>,
    /// Whether a Ctrl + left drag is moving an instance.
    moving: bool,
}

/// The sun's clock: hour of local solar time, latitude and day of the year.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TimeOfDay {
    pub hour: f32,
    pub latitude: f32,
    pub day: f32,
}

/// Textures the window made for this frame, as egui shows them.
#[derive(Default)]
pub(crate) struct Images {
    pub view: Option<(egui::TextureId, [u32; 2])>,
    pub maps: Option<(egui::TextureId, [u32; 2])>,
    pub density: Option<egui::TextureHandle>,
    pub error: Option<egui::TextureHandle>,
}

impl Model {
    pub fn new(
        scene: Scene,
        settings: Settings,
        baseline: Settings,
        source: SceneSource,
        show_panel: bool,
    ) -> anyhow::Result<Self> {
        let camera = settings.resolve_camera(&scene)?;
        Ok(Self {
            form: SettingsForm::new(),
            rig: CameraRig::looking(camera.eye, camera.target),
            settings,
            baseline,
            source,
            scene: Arc::new(scene),
            view: View::Lit,
            show_panel,
            show_maps: false,
            messages: Vec::new(),
            drafts: BTreeMap::new(),
            timings: VecDeque::new(),
            lights: Vec::new(),
            view_size: [960, 720],
            view_rect: [0, 0, 960, 720],
            save_path: "view.toml".into(),
            time_of_day: TimeOfDay { hour: 15.0, latitude: 45.0, day: 172.0 },
            density: None,
            error_job: None,
            error: None,
            pending: Vec::new(),
            moving: false,
        })
    }

    /// The settings a frame is rendered with: the panel's, with the rig's camera and
    /// the view's size.
    pub fn frame_settings(&self) -> Settings {
        let mut s = self.settings.clone();
        s.camera.eye = Some(self.rig.eye());
        s.camera.target = Some(self.rig.target);
        s.image.width = self.view_size[0].max(16);
        s.image.height = self.view_size[1].max(16);
        s
    }

    pub fn say(&mut self, message: impl Into<String>) {
        let message = message.into();
        crate::status_line::say(&message);
        self.messages.push(message);
    }

    /// Sets one setting through the form, as its flag would on the command line;
    /// a refused value is reported and changes nothing.
    pub fn set(&mut self, id: &str, value: Option<&str>) {
        match self.form.set(&self.settings, id, value) {
            Ok(settings) => {
                if id == "eye" || id == "target" {
                    let camera = settings.resolve_camera(&self.scene);
                    if let Ok(camera) = camera {
                        let mode = self.rig.mode;
                        self.rig = CameraRig::looking(camera.eye, camera.target);
                        self.rig.mode = mode;
                    }
                }
                self.settings = settings;
            }
            Err(e) => self.say(e),
        }
    }

    /// Shows `scene` from its own camera, as if opened from `source`; the debug
    /// pictures of the old one are dropped.
    pub fn show_scene(&mut self, scene: Scene, source: SceneSource) {
        self.settings.camera.eye = None;
        self.settings.camera.target = None;
        match self.settings.resolve_camera(&scene) {
            Ok(camera) => {
                let mode = self.rig.mode;
                self.rig = CameraRig::looking(camera.eye, camera.target);
                self.rig.mode = mode;
            }
            Err(e) => self.say(e.to_string()),
        }
        let name = scene.name.clone();
        self.scene = Arc::new(scene);
        self.source = source;
        self.density = None;
        self.error = None;
        self.error_job = None;
        self.view = View::Lit;
        self.say(format!("showing {name}"));
    }

    /// Turns or moves the light by a drag of (dx, dy) pixels: the sun's azimuth and
    /// elevation, or a spot or point light across the view.
    pub fn drag_light(&mut self, dx: f32, dy: f32) {
        let light = match self.settings.resolve_light(&self.scene) {
            Ok(light) => light,
            Err(e) => return self.say(e.to_string()),
        };
        let (right, up) = self.rig.right_up();
        let world_per_pixel = self.rig.distance() / self.view_size[1].max(1) as f32;
        let moved = |p: Vec3| p + (right * dx - up * dy) * world_per_pixel;
        let xyz = |p: Vec3| format!("{},{},{}", p.x, p.y, p.z);
        // By where the light is, not by its kind: a light from infinitely far turns, a
        // local one moves. Each kind's settings are named after it (`sun_azimuth`,
        // `spot_position`).
        let kind = light.type_name();
        match light.emission().origin {
            Origin::Infinite { travel } => {
                let to_light = -travel;
                let elevation = to_light.y.clamp(-1.0, 1.0).asin().to_degrees();
                let azimuth = to_light.x.atan2(to_light.z).to_degrees();
                let azimuth = (azimuth + 0.4 * dx).rem_euclid(360.0);
                let elevation = (elevation - 0.3 * dy).clamp(1.0, 90.0);
                self.set(&format!("{kind}_azimuth"), Some(&azimuth.to_string()));
                self.set(&format!("{kind}_elevation"), Some(&elevation.to_string()));
            }
            Origin::Local { position, .. } => {
                self.set(&format!("{kind}_position"), Some(&xyz(moved(position))))
            }
        }
    }

    /// Puts the sun where the time-of-day control says.
    fn place_sun(&mut self) {
        let t = self.time_of_day;
        let sun = solar::sun_position(t.hour, t.latitude, solar::declination_degrees(t.day));
        if sun.elevation < 1.0 {
            self.say(format!("at {:.1} h the sun is below the horizon; it stays at 1°", t.hour));
        }
        self.set("sun_elevation", Some(&sun.elevation.max(1.0).to_string()));
        self.set("sun_azimuth", Some(&sun.azimuth.to_string()));
    }

    /// Draws every panel and the central view, which takes the camera and light drags.
    pub fn ui(&mut self, ui: &mut egui::Ui, images: &Images) {
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        if self.show_panel {
            egui::Panel::left("settings").default_size(340.0).resizable(true).show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.settings_panel(ui));
            });
            egui::Panel::right("inspect").default_size(300.0).resizable(true).show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.inspect_panel(ui, images));
            });
        }
        egui::CentralPanel::default().frame(egui::Frame::NONE).show(ui, |ui| self.central_view(ui, images));
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let mode = match self.rig.mode {
                CameraMode::Orbit => "orbit",
                CameraMode::Fly => "fly",
            };
            ui.label(format!(
                "camera: {mode} (C switches) · left drag turns · Ctrl + left drag moves an object · right drag moves the light · middle drag pans · \
                 scroll zooms{} · F1 panels · F12 screenshot",
                if self.rig.mode == CameraMode::Fly { " · W A S D Q E fly" } else { "" }
            ));
        });
        // Always two lines, so that a message does not resize the view.
        let last = self.messages.last().map_or("", String::as_str);
        ui.label(RichText::new(last).color(Color32::from_rgb(240, 200, 120)));
    }

    /// The settings panel: one widget per flag, grouped by `--help` heading.
    fn settings_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Settings");
        ui.label("Every control is a `gnomon render` flag; hover for its help.");
        let values = self.form.values(&self.settings);
        let mut edits: Vec<(String, Option<String>)> = Vec::new();
        let mut headings: Vec<String> = Vec::new();
        for field in self.form.fields() {
            if !headings.contains(&field.heading) {
                headings.push(field.heading.clone());
            }
        }
        for heading in &headings {
            let open = matches!(heading.as_str(), "Shadow filter" | "Shadow bias" | "Shadow map" | "Light");
            egui::CollapsingHeader::new(heading).default_open(open).show(ui, |ui| {
                egui::Grid::new(heading).num_columns(2).striped(true).show(ui, |ui| {
                    for field in self.form.fields().iter().filter(|f| &f.heading == heading) {
                        ui.label(&field.long).on_hover_text(&field.help);
                        let current = values.get(&field.id).cloned();
                        // The window decides the image size and the camera (drag it).
                        let driven = matches!(field.id.as_str(), "width" | "height");
                        let response = ui.add_enabled_ui(!driven, |ui| {
                            field_widget(ui, field, current.as_deref(), &mut self.drafts, &mut edits)
                        });
                        let help = if driven {
                            format!("{}\n\nIn the viewer the window's size decides it.", field.help)
                        } else {
                            field.help.clone()
                        };
                        response.response.on_hover_text(help);
                        ui.end_row();
                    }
                });
            });
        }
        for (id, value) in edits {
            self.pending.push(Action::Set { id, value });
        }
    }

    pub fn record_timings(&mut self, timings: Option<PassTimings>, lights: Vec<LightStats>) {
        if let Some(t) = timings {
            self.timings.push_back(t);
            while self.timings.len() > TIMING_WINDOW {
                self.timings.pop_front();
            }
        }
        self.lights = lights;
    }

    /// The central view: the image, taking the camera and light drags.
    fn central_view(&mut self, ui: &mut egui::Ui, images: &Images) {
        let rect = ui.available_rect_before_wrap();
        let ppp = ui.ctx().pixels_per_point();
        self.view_size = [(rect.width() * ppp).round() as u32, (rect.height() * ppp).round() as u32];
        let [x, y] = [(rect.left() * ppp).round() as u32, (rect.top() * ppp).round() as u32];
        self.view_rect = [x, y, self.view_size[0], self.view_size[1]];
        let picture = match self.view {
            View::Lit => images.view.map(|(id, _)| id),
            View::TexelDensity => images.density.as_ref().map(|t| t.id()),
            View::Error => images.error.as_ref().map(|t| t.id()).or(images.view.map(|(id, _)| id)),
        };
        let response = match picture {
            Some(id) => ui.add(egui::Image::new((id, rect.size())).sense(egui::Sense::click_and_drag())),
            None => ui.allocate_rect(rect, egui::Sense::click_and_drag()),
        };
        let caption = match self.view {
            View::Lit => None,
            View::TexelDensity => self.density.as_ref().map(|p| p.summary.clone()),
            View::Error if self.error.is_none() => {
                Some("no comparison yet: press Compare with the reference".into())
            }
            View::Error => self.error.as_ref().map(|p| p.summary.clone()),
        };
        if let Some(caption) = caption {
            ui.painter().text(
                rect.left_top() + egui::vec2(8.0, 8.0),
                egui::Align2::LEFT_TOP,
                caption,
                egui::FontId::proportional(14.0),
                Color32::WHITE,
            );
        }
        let delta = response.drag_delta() * ppp;
        // Ctrl + left drag moves the instance under the cursor (`drag.rs`): it is
        // grabbed where the button went down, not where the drag was recognized.
        let (ctrl, press) = ui.input(|i| (i.modifiers.ctrl, i.pointer.press_origin()));
        let at =
            |pos: egui::Pos2| [(pos.x - rect.left()) / rect.width(), (pos.y - rect.top()) / rect.height()];
        let pointer = response.interact_pointer_pos();
        if ctrl && response.drag_started_by(egui::PointerButton::Primary) {
            if let Some(pos) = press.or(pointer) {
                self.pending.push(Action::Grab(crate::Grip::At(at(pos))));
                self.moving = true;
            }
        } else if self.moving {
            // The last movement too, on the frame the button comes up.
            if let Some(pos) = pointer.or(response.hover_pos()) {
                self.pending.push(Action::DragTo(at(pos)));
            }
            if response.drag_stopped() {
                self.pending.push(Action::Release);
                self.moving = false;
            }
        } else if response.dragged_by(egui::PointerButton::Primary) {
            self.rig.turn(delta.x, delta.y);
        } else if response.dragged_by(egui::PointerButton::Secondary) {
            self.drag_light(delta.x, delta.y);
        } else if response.dragged_by(egui::PointerButton::Middle) {
            let fov = self.settings.resolve_camera(&self.scene).map(|c| c.fov_y_degrees).unwrap_or(45.0);
            self.rig.pan(delta.x, delta.y, fov.to_radians(), self.view_size[1] as f32);
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                match self.rig.mode {
                    CameraMode::Orbit => self.rig.zoom(scroll / 50.0),
                    CameraMode::Fly => self.rig.fly(scroll / 50.0 * 0.1 * self.rig.distance(), 0.0, 0.0),
                }
            }
        }
        if !ui.ctx().egui_wants_keyboard_input() {
            self.keys(ui);
        }
    }

    fn keys(&mut self, ui: &mut egui::Ui) {
        let (dt, pressed) = ui.input(|i| {
            let held = |k| if i.key_down(k) { 1.0 } else { 0.0 };
            let axes = [
                held(egui::Key::W) - held(egui::Key::S),
                held(egui::Key::D) - held(egui::Key::A),
                held(egui::Key::E) - held(egui::Key::Q),
            ];
            (
                (i.stable_dt.min(0.25), axes),
                [i.key_pressed(egui::Key::C), i.key_pressed(egui::Key::F1), i.key_pressed(egui::Key::F12)],
            )
        });
        let (dt, [forward, right, up]) = dt;
        if self.rig.mode == CameraMode::Fly && (forward != 0.0 || right != 0.0 || up != 0.0) {
            // Half the scene's size a second.
            let speed = 0.5 * self.scene.bounds().bounding_radius().max(1e-3) * dt;
            self.rig.fly(forward * speed, right * speed, up * speed);
        }
        let [camera, panel, screenshot] = pressed;
        if camera {
            self.rig.mode = match self.rig.mode {
                CameraMode::Orbit => CameraMode::Fly,
                CameraMode::Fly => CameraMode::Orbit,
            };
        }
        if panel {
            self.show_panel = !self.show_panel;
        }
        if screenshot {
            let name = format!(
                "gnomon-view-{}-{}.png",
                self.settings.shadow.filter.technique.name(),
                web_time::SystemTime::now()
                    .duration_since(web_time::UNIX_EPOCH)
                    .map(|d| d.as_secs())
                    .unwrap_or_default()
            );
            self.pending.push(Action::Screenshot(name.into()));
        }
    }
}

/// Three drag values for a position; true when one changed.
fn vec3_drag(ui: &mut egui::Ui, label: &str, p: &mut Vec3, scale: f32) -> bool {
    let speed = (scale * 0.005).max(1e-3);
    ui.horizontal(|ui| {
        let mut changed = false;
        for v in [&mut p.x, &mut p.y, &mut p.z] {
            changed |= ui.add(egui::DragValue::new(v).speed(speed).max_decimals(3)).changed();
        }
        ui.label(label);
        changed
    })
    .inner
}

/// One field's widget; an edit is pushed onto `edits` as flag text.
fn field_widget(
    ui: &mut egui::Ui,
    field: &crate::settings_form::Field,
    current: Option<&str>,
    drafts: &mut BTreeMap<String, String>,
    edits: &mut Vec<(String, Option<String>)>,
) {
    let id = field.id.clone();
    match (&field.kind, current) {
        (FieldKind::Choice(choices), Some(value)) => {
            let mut chosen = value.to_string();
            egui::ComboBox::from_id_salt(&id).selected_text(&chosen).show_ui(ui, |ui| {
                for (name, help) in choices {
                    ui.selectable_value(&mut chosen, name.clone(), name).on_hover_text(help);
                }
            });
            if chosen != value {
                edits.push((id, Some(chosen)));
            }
        }
        (FieldKind::Flag | FieldKind::Bool, Some(value)) => {
            let mut on = value == "true";
            if ui.checkbox(&mut on, "").changed() {
                edits.push((id, Some(on.to_string())));
            }
        }
        (FieldKind::Integer, Some(value)) if !field.optional => {
            let mut n: i64 = value.parse().unwrap_or_default();
            let speed = (n.abs() as f64 * 0.02).max(0.05);
            let mut drag = egui::DragValue::new(&mut n).speed(speed);
            if let Some(r) = field.range {
                drag = drag.range(r.min.ceil() as i64..=r.max.floor() as i64);
            }
            if ui.add(drag).changed() {
                edits.push((id, Some(n.to_string())));
            }
        }
        (FieldKind::Float, Some(value)) if !field.optional => {
            let mut x: f32 = value.parse().unwrap_or_default();
            let speed = (x.abs() * 0.01).max(1e-3);
            let mut drag = egui::DragValue::new(&mut x).speed(speed).max_decimals(4);
            if let Some(r) = field.range {
                // An open end is left to the check, which names it when reached.
                drag = drag.range(r.min as f32..=r.max as f32);
            }
            if ui.add(drag).changed() {
                edits.push((id, Some(x.to_string())));
            }
        }
        (FieldKind::Integer | FieldKind::Float | FieldKind::Text, _)
        | (FieldKind::Choice(_) | FieldKind::Flag | FieldKind::Bool, None) => {
            // Text: vectors, and the optional fields (empty gives them back to the scene).
            let draft = drafts.entry(id.clone()).or_insert_with(|| current.unwrap_or_default().to_string());
            let hint = match (field.optional, &field.value_name) {
                (true, Some(v)) => format!("the scene's ({v})"),
                (true, None) => "the scene's".to_string(),
                (false, v) => v.clone().unwrap_or_default(),
            };
            let response = ui.add(egui::TextEdit::singleline(draft).hint_text(hint).desired_width(140.0));
            if response.lost_focus() {
                let text = draft.trim().to_string();
                if Some(text.as_str()) != current && !(text.is_empty() && current.is_none()) {
                    edits.push((id.clone(), (!text.is_empty()).then_some(text)));
                }
                drafts.remove(&id);
            } else if !response.has_focus() {
                *draft = current.unwrap_or_default().to_string();
            }
        }
    }
}
