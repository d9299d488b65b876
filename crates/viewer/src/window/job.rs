//! A frame's GPU work as a value that owns what it needs, the renderer included, so
//! that it can run to its end while the window goes on. On the desktop it is waited
//! for at once; a browser cannot wait for the GPU, so there it runs as a task and
//! comes back as an event ([`super::platform`]). While it is away the panels still
//! draw, and the actions that need the renderer wait for it to come back.

use std::sync::Arc;

use gnomon_render::{Frame, GpuScene, LiveFrame, OutputRequest, RenderError, Renderer};
use gnomon_scene::{Scene, Settings, memory::Window, settings::Technique};

/// The renderer and the scene it holds on the GPU: what a frame's work takes away.
pub(crate) struct Workshop {
    pub renderer: Renderer,
    pub uploaded: GpuScene,
    /// The largest image the renderer's memory budget has room for: the image is as
    /// large as the window, a size the user chose, not a file.
    pub room: Window,
}

impl Workshop {
    /// A workshop whose budget has room for images up to `room`.
    pub fn new(mut renderer: Renderer, uploaded: GpuScene, room: Window) -> Result<Self, RenderError> {
        renderer.make_room_for_window(room)?;
        Ok(Self { renderer, uploaded, room })
    }

    /// Grows the budget's room to an image of `width` × `height` where it has none
    /// yet (a window dragged onto a larger monitor, or wider than any one).
    pub fn make_room(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        if width <= self.room.width && height <= self.room.height {
            return Ok(());
        }
        let room = Window { width: width.max(self.room.width), height: height.max(self.room.height) };
        self.renderer.make_room_for_window(room)?;
        self.room = room;
        Ok(())
    }
}

/// What a frame reads back besides its live image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct ReadBack {
    /// The frame, for the texel-density view.
    pub density: bool,
    /// The frame, to compare with the reference.
    pub compare: bool,
    /// The same view drawn by the GPU's `raytraced`, the truth a browser compares
    /// with (it has no threads for the CPU reference).
    pub raytraced: bool,
}

impl ReadBack {
    fn any(self) -> bool {
        self.density || self.compare
    }
}

/// One frame's work.
pub(crate) struct FrameJob {
    pub workshop: Workshop,
    pub scene: Arc<Scene>,
    pub settings: Settings,
    pub read_back: ReadBack,
}

/// One frame's work, done: the workshop back, and what it made.
pub(crate) struct FrameDone {
    pub workshop: Workshop,
    /// The settings it was rendered with.
    pub settings: Settings,
    pub read_back: ReadBack,
    pub live: Result<LiveFrame, RenderError>,
    /// The frame read back, when `read_back` asked for it.
    pub frame: Option<Result<Frame, RenderError>>,
    /// The same view drawn by `raytraced`, when `read_back` asked for it.
    pub traced: Option<Result<Frame, RenderError>>,
}

impl FrameJob {
    /// Renders the live frame, then what `read_back` asks for, in the order the
    /// window shows them (the live frame's textures stay valid until the next live
    /// frame).
    pub async fn run(self) -> FrameDone {
        let FrameJob { mut workshop, scene, settings, read_back } = self;
        let Workshop { renderer, uploaded, .. } = &mut workshop;
        let live = renderer.render_live_async(uploaded, &scene, &settings).await;
        let request = OutputRequest::default();
        let mut frame = None;
        if read_back.any() {
            frame = Some(renderer.render_uploaded_async(uploaded, &scene, &settings, &request).await);
        }
        let mut traced = None;
        if read_back.raytraced {
            let mut raytraced = settings.clone();
            raytraced.shadow.filter.technique = Technique::RAYTRACED;
            traced = Some(renderer.render_uploaded_async(uploaded, &scene, &raytraced, &request).await);
        }
        FrameDone { workshop, settings, read_back, live, frame, traced }
    }
}
