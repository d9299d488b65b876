//! Moving an instance by hand. Ctrl + left drag on the view picks the instance under
//! the cursor: a ray through the pixel, traced on the CPU against the scene
//! (`gnomon_reference::TracedScene`). The drag then carries the instance across the plane
//! through the picked point that faces the camera.
//!
//! While it is held, the instance is a moving caster (`Motion::Dynamic`). Kept shadow
//! maps then keep the rest of the scene and draw the held instance over a copy each
//! frame, instead of drawing every layer it crosses again. Released, it takes back
//! the motion it had.

use std::sync::Arc;

use glam::{Mat4, Vec3};
use gnomon_render::{GpuScene, Renderer};
use gnomon_scene::{Camera, Motion, Scene};

use crate::{Action, ui::Model};

/// What a grab takes hold of.
#[derive(Clone, Debug, PartialEq)]
pub enum Grip {
    /// The instance under a point of the view, in fractions of its width and height
    /// from its top-left corner.
    At([f32; 2]),
    /// The instance of this name (for scripts).
    Named(String),
}

/// The instance being moved.
#[derive(Clone, Debug)]
pub(crate) struct Held {
    pub instance: usize,
    /// Its motion before it was grabbed, given back on release.
    before: Motion,
    /// The plane it moves across: through the picked point, facing the camera.
    plane_point: Vec3,
    plane_normal: Vec3,
}

/// A ray from the camera through a point of the view (fractions of its width and
/// height from its top-left corner), for an image of `aspect` = width / height:
/// origin and unit direction.
pub(crate) fn ray_through(camera: &Camera, aspect: f32, point: [f32; 2]) -> (Vec3, Vec3) {
    let world_from_clip = camera.clip_from_world(aspect).inverse();
    // NDC x runs right, y up: the view's y runs down.
    let ndc = glam::Vec2::new(2.0 * point[0] - 1.0, 1.0 - 2.0 * point[1]);
    let far = world_from_clip.project_point3(ndc.extend(1.0));
    (camera.eye, (far - camera.eye).normalize_or(camera.target - camera.eye))
}

/// Where the ray meets the plane, if it does ahead of its origin.
fn plane_hit(origin: Vec3, direction: Vec3, point: Vec3, normal: Vec3) -> Option<Vec3> {
    let facing = direction.dot(normal);
    if facing.abs() < 1e-6 {
        return None;
    }
    let t = (point - origin).dot(normal) / facing;
    (t > 0.0).then(|| origin + t * direction)
}

/// What a grab found: the instance and the plane it will move across.
pub(crate) fn grab(scene: &Scene, camera: &Camera, aspect: f32, grip: &Grip) -> Result<Held, String> {
    let facing = (camera.target - camera.eye).normalize_or(Vec3::NEG_Z);
    let (instance, point) = match grip {
        Grip::At(at) => {
            let (origin, direction) = ray_through(camera, aspect, *at);
            let tracer = gnomon_reference::TracedScene::build(scene);
            let hit = tracer
                .intersect(origin, direction, 0.0, f32::INFINITY)
                .ok_or_else(|| "nothing under the cursor to move".to_string())?;
            (hit.object_id as usize - 1, hit.position)
        }
        Grip::Named(name) => {
            let index = scene
                .instances
                .iter()
                .position(|i| &i.name == name)
                .ok_or_else(|| format!("no instance named `{name}` to move"))?;
            let centre = scene.meshes[scene.instances[index].mesh].bounds().center();
            (index, scene.instances[index].world_from_object.transform_point3(centre))
        }
    };
    Ok(Held { instance, before: scene.instances[instance].motion, plane_point: point, plane_normal: -facing })
}

impl Held {
    /// Marks the held instance as moving, and uploads the scene again so that its
    /// batch is drawn over the kept maps rather than into them.
    pub fn take(
        &self,
        scene: &mut Scene,
        renderer: &Renderer,
        uploaded: &mut GpuScene,
    ) -> anyhow::Result<()> {
        set_motion(scene, self.instance, Motion::Dynamic, renderer, uploaded)
    }

    /// Gives the instance back the motion it had.
    pub fn release(
        &self,
        scene: &mut Scene,
        renderer: &Renderer,
        uploaded: &mut GpuScene,
    ) -> anyhow::Result<()> {
        set_motion(scene, self.instance, self.before, renderer, uploaded)
    }

    /// The world offset that carries the grabbed point to where the ray through
    /// `point` of the view meets the plane; None where the ray misses it.
    pub fn offset_to(&self, camera: &Camera, aspect: f32, point: [f32; 2]) -> Option<Vec3> {
        let (origin, direction) = ray_through(camera, aspect, point);
        plane_hit(origin, direction, self.plane_point, self.plane_normal).map(|p| p - self.plane_point)
    }

    /// Moves the instance by `by` in the world, on the GPU too.
    pub fn move_by(
        &mut self,
        by: Vec3,
        scene: &mut Scene,
        renderer: &mut Renderer,
        uploaded: &mut GpuScene,
    ) -> anyhow::Result<()> {
        let placed = &mut scene.instances[self.instance].world_from_object;
        *placed = Mat4::from_translation(by) * *placed;
        self.plane_point += by;
        renderer.move_instances(uploaded, scene, &[self.instance])?;
        Ok(())
    }
}

/// Gives instance `instance` `motion`, uploading the scene again (motion decides how
/// instances are batched, `gpu_scene::batches`); where the upload fails, the scene
/// keeps its motion, in step with what the GPU holds.
fn set_motion(
    scene: &mut Scene,
    instance: usize,
    motion: Motion,
    renderer: &Renderer,
    uploaded: &mut GpuScene,
) -> anyhow::Result<()> {
    let before = scene.instances[instance].motion;
    if before == motion {
        return Ok(());
    }
    scene.instances[instance].motion = motion;
    match renderer.upload(scene) {
        Ok(again) => {
            *uploaded = again;
            Ok(())
        }
        Err(e) => {
            scene.instances[instance].motion = before;
            Err(e.into())
        }
    }
}

/// The viewer's hand: what it holds, and the actions that grab, carry and release.
#[derive(Default)]
pub(crate) struct Hand {
    pub held: Option<Held>,
}

/// What the hand acts on: the viewer's model and the renderer with its upload.
pub(crate) struct Reach<'a> {
    pub model: &'a mut Model,
    pub renderer: &'a mut Renderer,
    pub uploaded: &'a mut GpuScene,
}

impl Hand {
    /// Carries out a grab, drag, move or release; what fails is said in the status
    /// line. Returns the name of an instance newly grabbed.
    pub fn act(&mut self, action: &Action, reach: Reach) -> Option<String> {
        let Reach { model, renderer, uploaded } = reach;
        let settings = model.frame_settings();
        let camera = match settings.resolve_camera(&model.scene) {
            Ok(camera) => camera,
            Err(e) => {
                model.say(e.to_string());
                return None;
            }
        };
        let aspect = settings.image.width as f32 / settings.image.height as f32;
        // One object at a time: a new grab lets go of the one held.
        if matches!(action, Action::Grab(_))
            && let Some(held) = self.held.take()
            && let Err(e) = held.release(Arc::make_mut(&mut model.scene), renderer, uploaded)
        {
            model.say(format!("{e:#}"));
        }
        let result = match (action, self.held.as_mut()) {
            (Action::Grab(grip), _) => match grab(&model.scene, &camera, aspect, grip) {
                Ok(held) => {
                    let name = model.scene.instances[held.instance].name.clone();
                    match held.take(Arc::make_mut(&mut model.scene), renderer, uploaded) {
                        Ok(()) => {
                            self.held = Some(held);
                            model.say(format!("moving {name}: a moving caster while held"));
                            return Some(name);
                        }
                        Err(e) => Err(e),
                    }
                }
                Err(why) => Err(anyhow::anyhow!(why)),
            },
            (Action::DragTo(point), Some(held)) => match held.offset_to(&camera, aspect, *point) {
                Some(by) => held.move_by(by, Arc::make_mut(&mut model.scene), renderer, uploaded),
                None => Ok(()),
            },
            (Action::MoveHeldBy(by), Some(held)) => {
                held.move_by(Vec3::from_array(*by), Arc::make_mut(&mut model.scene), renderer, uploaded)
            }
            (Action::Release, Some(held)) => {
                let released = held.release(Arc::make_mut(&mut model.scene), renderer, uploaded);
                let name = model.scene.instances[held.instance].name.clone();
                self.held = None;
                model.say(format!("released {name}"));
                released
            }
            (Action::DragTo(_) | Action::MoveHeldBy(_) | Action::Release, None) => Ok(()),
            (
                Action::Set { .. }
                | Action::Screenshot(_)
                | Action::CopyCommand
                | Action::SaveSceneFile(_)
                | Action::CompareWithReference
                | Action::Show(_),
                _,
            ) => Ok(()),
        };
        if let Err(e) = result {
            model.say(format!("{e:#}"));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_through_the_centre_runs_along_the_view() {
        let camera = gnomon_scene::builtin::spheres().camera;
        let (origin, direction) = ray_through(&camera, 1.5, [0.5, 0.5]);
        assert_eq!(origin, camera.eye);
        let along = (camera.target - camera.eye).normalize();
        assert!(direction.dot(along) > 0.99999, "{direction} against {along}");
        // The top-left corner of the view is up and left of the centre.
        let (_, corner) = ray_through(&camera, 1.5, [0.0, 0.0]);
        let view = camera.view_from_world().transform_vector3(corner);
        assert!(view.x < 0.0 && view.y > 0.0, "{view}");
    }

    #[test]
    fn a_grab_picks_the_instance_under_the_cursor_and_moves_it_across_the_view() {
        let scene = gnomon_scene::builtin::spheres();
        let target = scene.instances.iter().position(|i| i.name == "sphere 1,1").unwrap();
        let centre = scene.meshes[scene.instances[target].mesh].bounds().center();
        let centre = scene.instances[target].world_from_object.transform_point3(centre);
        // A camera looking down at the sphere from above, where nothing stands between.
        let camera = Camera { eye: centre + Vec3::new(0.0, 6.0, 1.0), target: centre, ..scene.camera };
        let held = grab(&scene, &camera, 1.0, &Grip::At([0.5, 0.5])).expect("a hit");
        assert_eq!(held.instance, target);
        assert_eq!(held.before, Motion::Static);
        // A point to the right of the centre carries it right, in the plane facing the camera.
        let by = held.offset_to(&camera, 1.0, [0.6, 0.5]).expect("the plane ahead");
        let right = camera.view_from_world().inverse().transform_vector3(Vec3::X);
        assert!(by.dot(right) > 0.1, "{by}");
        let along = (camera.target - camera.eye).normalize();
        assert!(by.dot(along).abs() < 1e-4 * by.length(), "{by} stays in the plane");
        let by_name = grab(&scene, &camera, 1.0, &Grip::Named("sphere 1,1".into())).unwrap();
        assert_eq!(by_name.instance, target);
        assert!(grab(&scene, &camera, 1.0, &Grip::Named("nobody".into())).is_err());
        // Straight up into the sky, nothing.
        let sky =
            Camera { eye: Vec3::new(0.0, 50.0, 0.0), target: Vec3::new(0.0, 100.0, 1.0), ..scene.camera };
        assert!(grab(&scene, &sky, 1.0, &Grip::At([0.5, 0.5])).is_err());
    }
}
