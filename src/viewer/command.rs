//! What the user asked for in a frame. Panels and shortcuts return commands;
//! the app applies them once the frame's UI is drawn, so no panel does I/O
//! or reaches into the app (the pattern of the egui demo and Rerun).

#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Pick a scene file in a dialog and open it.
    Open,
    /// Read the scene file again, keeping the camera.
    Reload,
    /// Write the edits into the scene file (or ask where, for a scene
    /// that has no TOML file of its own).
    Save,
    /// Write the scene with its edits to a new TOML file.
    SaveAs,
    /// Step back through the edits.
    Undo,
    /// Step forward again.
    Redo,
    /// Stop the pass being rendered, keeping the image as far as it got.
    StopPass,
    /// Write the frame on screen to a PNG.
    Export,
    /// Back to the scene's camera.
    ResetCamera,
    /// Trace pixel `(x, y)`'s ray tree and show it.
    InspectPixel(u32, u32),
    /// Keep the frame on screen as "A" of an A/B comparison.
    PinAsA,
    /// Edit the octree parameters: the tree is rebuilt and the passes
    /// render again (the same image, in the new tree's time).
    SetOctreeParams(crate::accel::OctreeParams),
    /// Work out a suggested octree setting in the background.
    SuggestOctree,
    /// Sample the view's rays through the current tree in the background
    /// (asked for by the octree panel while it is open).
    SampleRays,
    /// Record, play or edit the camera path.
    CameraPath(PathCommand),
    Quit,
}

/// What the camera path panel and its shortcuts ask for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathCommand {
    /// Start recording camera moves as keyframes, or stop.
    ToggleRecording,
    /// Play the path back, or stop.
    TogglePlaying,
    /// Add the camera as it is as a keyframe after the last.
    AddKeyframe,
    /// Delete keyframe `n`.
    Delete(usize),
    /// Delete the whole path.
    Clear,
}
