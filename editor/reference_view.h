// The editor's "Render reference" (scene/reference_render.h): the Monte Carlo image of the scene and
// view as they were when asked, traced on a background task of its own with its progress and Cancel,
// and a window that shows it beside the live image and a map of where they differ. UI-thread state;
// editing, the live solve and loading go on while the trace runs.
#pragma once

#include "editor/background_task.h"
#include "gl/gl_context.h"
#include "scene/reference_render.h"

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace waxwork {

class ReferenceView {
public:
    // The trace's size as a fraction of the view's: 1/4, 1/2 or all of its pixels across.
    static constexpr std::array<int, 3> kSizeDivisors{4, 2, 1};
    struct Settings {
        int size = 0;                     // index into kSizeDivisors
        float seconds = 30;               // the trace's time limit
        float target_error_percent = 5;   // and its noise target (whichever comes first)
    };

    explicit ReferenceView(const GlApi& gl) : gl_(gl) {}
    ~ReferenceView();  // deletes the textures; the task's destructor cancels the trace and joins it
    ReferenceView(const ReferenceView&) = delete;
    ReferenceView& operator=(const ReferenceView&) = delete;

    Settings& settings() { return settings_; }
    // The trace's pixel size for a view of `view_w` x `view_h` pixels (at least 16 x 16 pixels).
    std::array<int, 2> image_size(int view_w, int view_h) const;

    // Traces `scene` through `camera` with the settings. `scene_version` tags the result: when the
    // window's scene has moved on, the window says the reference shows an earlier state. Throws
    // std::logic_error while a trace runs.
    void start(std::shared_ptr<const ReferenceScene> scene, const PixelCamera& camera, long long scene_version);
    bool busy() const { return task_.busy(); }
    void cancel() { task_.cancel(); }
    const BackgroundTask& task() const { return task_; }

    // Once per frame: installs a finished trace and returns the status line of what ended (finished,
    // cancelled or failed); nullopt while nothing ended.
    std::optional<std::string> poll();

    // What the window's buttons ask the editor for.
    enum class Request { None, Render, Save };
    // The Reference window (when shown): the settings, Render, the progress with Cancel, the three
    // images and their numbers, Save. `scene_version` as for start.
    // `x`, `y`: where the window first opens (window coordinates; the user may move it).
    Request draw(long long scene_version, float ui_scale, float x, float y);
    // Asks the window to show (View > Render reference opens it even before the first result).
    void show() { open_ = true; }
    // Another document was opened: cancels the trace and forgets the result (a trace that ends later
    // installs nothing).
    void clear();

    const ReferenceComparison* result() const { return result_ ? &*result_ : nullptr; }
    // Writes the comparison shown (save_reference_comparison). Throws InvalidArgumentError when there
    // is no result yet, and what the save throws.
    void save(const std::filesystem::path& png) const;

private:
    void upload();
    void delete_textures();

    const GlApi& gl_;
    Settings settings_;
    BackgroundTask task_;
    std::optional<ReferenceComparison> result_;
    long long result_version_ = -1;
    long long generation_ = 0;  // moved by clear(): a trace started before installs nothing
    bool open_ = false;
    bool own_exposure_ = false;  // show the traced image at its own exposure and the scaled difference
    // live, traced at the live exposure, traced at its own, difference, scaled difference
    std::array<GLuint, 5> textures_{};
};

}  // namespace waxwork
