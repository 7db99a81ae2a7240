#include "editor/reference_view.h"

#include "base/thread_priority.h"
#include "render/difference_map.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

namespace waxwork {

namespace {

// The smallest trace: fewer pixels than this across shows nothing worth comparing.
constexpr int kMinReferencePixels = 16;

ImTextureID texture_id(GLuint texture) { return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture)); }

void legend_swatch(const std::array<uint8_t, 3>& c, const char* label) {
    ImGui::ColorButton(label, ImVec4(c[0] / 255.0f, c[1] / 255.0f, c[2] / 255.0f, 1.0f),
                       ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoDragDrop);
    ImGui::SameLine();
    ImGui::TextUnformatted(label);
}

}  // namespace

ReferenceView::~ReferenceView() { delete_textures(); }

std::array<int, 2> ReferenceView::image_size(int view_w, int view_h) const {
    const int divisor = kSizeDivisors[std::clamp(settings_.size, 0, static_cast<int>(kSizeDivisors.size()) - 1)];
    return {std::max(kMinReferencePixels, view_w / divisor), std::max(kMinReferencePixels, view_h / divisor)};
}

void ReferenceView::start(std::shared_ptr<const ReferenceScene> scene, const PixelCamera& camera, long long scene_version) {
    ReferenceOptions options;
    options.max_seconds = std::max(0.0f, settings_.seconds);
    options.target_error = std::clamp(settings_.target_error_percent / 100.0, 0.0, 0.99);
    if (options.max_seconds == 0 && options.target_error == 0) options.max_seconds = Settings{}.seconds;
    open_ = true;
    const long long generation = generation_;
    task_.start("Reference", [scene = std::move(scene), camera, options, scene_version, generation, this](TaskProgress& progress) {
        // The trace's own thread (on two cores, the only one tracing) gives way to the window's.
        lower_this_thread_priority();
        auto traced = std::make_shared<ReferenceComparison>(render_reference(*scene, camera, options, &progress));
        // Runs on the UI thread (BackgroundTask::poll), the only place the view's state changes.
        return BackgroundTask::Apply([this, traced, scene_version, generation] {
            if (generation != generation_) return;
            result_ = std::move(*traced);
            result_version_ = scene_version;
            upload();
        });
    });
}

void ReferenceView::clear() {
    task_.cancel();
    ++generation_;
    result_.reset();
    delete_textures();
}

std::optional<std::string> ReferenceView::poll() {
    try {
        if (!task_.poll()) return std::nullopt;
        if (!result_) return std::string("Reference dropped: another document was opened");
    } catch (const CancelledError&) {
        return std::string("Reference cancelled");
    } catch (const std::exception& e) {
        return std::string("Reference failed: ") + e.what();
    }
    const MonteCarloImage& t = result_->traced;
    char line[200];
    std::snprintf(line, sizeof line, "Reference: %lld passes in %.1f s, noise %.1f %%; live against it: %.0f %% (%.0f %% after brightness x%.2f)",
                  static_cast<long long>(t.passes), t.seconds,
                  100 * *std::max_element(t.relative_error.begin(), t.relative_error.end()),
                  100 * result_->difference.relative_l2, 100 * result_->difference.scaled_relative_l2,
                  result_->difference.scale);
    return std::string(line);
}

void ReferenceView::save(const std::filesystem::path& png) const {
    if (!result_) throw InvalidArgumentError(png.string() + ": no reference rendered yet (View > Render reference)");
    save_reference_comparison(*result_, own_exposure_, png);
}

void ReferenceView::delete_textures() {
    if (textures_[0]) gl_.DeleteTextures(static_cast<GLsizei>(textures_.size()), textures_.data());
    textures_.fill(0);
}

void ReferenceView::upload() {
    delete_textures();
    gl_.GenTextures(static_cast<GLsizei>(textures_.size()), textures_.data());
    const ReferenceComparison& r = *result_;
    const Image* images[] = {&r.live_image, &r.traced_at_live_exposure, &r.traced_at_own_exposure, &r.difference_image,
                             &r.scaled_difference_image};
    for (size_t i = 0; i < textures_.size(); ++i) {
        gl_.BindTexture(GL_TEXTURE_2D, textures_[i]);
        gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);  // the trace's pixels, not a blur
        gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, images[i]->width, images[i]->height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                       images[i]->rgba.data());
    }
    gl_.BindTexture(GL_TEXTURE_2D, 0);
}

ReferenceView::Request ReferenceView::draw(long long scene_version, float ui_scale, float x, float y) {
    if (!open_) return Request::None;
    ImGui::SetNextWindowPos(ImVec2(x, y), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(760 * ui_scale, 360 * ui_scale), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("Reference", &open_)) {
        ImGui::End();
        return Request::None;
    }
    Request request = Request::None;
    static const char* sizes[] = {"1/4 of the view", "1/2 of the view", "the view's size"};
    ImGui::SetNextItemWidth(150 * ui_scale);
    ImGui::Combo("size", &settings_.size, sizes, static_cast<int>(kSizeDivisors.size()));
    ImGui::SameLine();
    ImGui::SetNextItemWidth(90 * ui_scale);
    ImGui::DragFloat("s at most", &settings_.seconds, 1.0f, 1.0f, 3600.0f, "%.0f");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(90 * ui_scale);
    ImGui::DragFloat("% noise", &settings_.target_error_percent, 0.1f, 0.5f, 50.0f, "%.1f");
    ImGui::SameLine();
    ImGui::BeginDisabled(task_.busy());
    if (ImGui::Button("Render")) request = Request::Render;
    ImGui::EndDisabled();
    if (result_) {
        ImGui::SameLine();
        if (ImGui::Button("Save...")) request = Request::Save;
    }
    if (task_.busy()) {
        const TaskProgress& p = *task_.progress();
        const float fraction = p.fraction();
        char overlay[160];
        std::snprintf(overlay, sizeof overlay, "%s (%.1f s)", p.stage().c_str(), task_.elapsed_seconds());
        ImGui::ProgressBar(fraction >= 0 ? fraction : 0.0f, ImVec2(420 * ui_scale, 0), overlay);
        ImGui::SameLine();
        ImGui::BeginDisabled(task_.cancel_requested());
        if (ImGui::Button("Cancel")) cancel();
        ImGui::EndDisabled();
    }
    if (!result_) {
        if (!task_.busy()) ImGui::TextWrapped("Render traces the view as it is now with Monte Carlo transport.");
        ImGui::End();
        return request;
    }
    const ReferenceComparison& r = *result_;
    if (result_version_ != scene_version)
        ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "The scene has changed since: this is the reference of an earlier state.");
    ImGui::Checkbox("Each at its own exposure (compare the light's shape, not its brightness)", &own_exposure_);
    // Three images across, as large as the window allows with the titles, legend and numbers visible.
    const float gap = 8 * ui_scale;
    const ImVec2 avail = ImGui::GetContentRegionAvail();
    const float aspect = static_cast<float>(r.live_image.width) / static_cast<float>(std::max(1, r.live_image.height));
    const float text_below = 4 * ImGui::GetFrameHeightWithSpacing();
    const float w = std::max(32.0f, std::min((avail.x - 2 * gap) / 3, (avail.y - text_below) * aspect));
    const float h = w / aspect;
    const char* titles[] = {"Live (diffusion, Eq. 3)", "Reference (Monte Carlo)", "Difference"};
    const GLuint shown[] = {textures_[0], own_exposure_ ? textures_[2] : textures_[1], own_exposure_ ? textures_[4] : textures_[3]};
    for (int i = 0; i < 3; ++i) {
        if (i) ImGui::SameLine(0, gap);
        ImGui::BeginGroup();
        ImGui::TextUnformatted(titles[i]);
        ImGui::Image(texture_id(shown[i]), ImVec2(w, h));
        ImGui::EndGroup();
    }
    char brighter[64], darker[64];
    const double full = 100 * DifferenceMapOptions{}.full_scale;
    std::snprintf(brighter, sizeof brighter, "live brighter by %.0f %% or more", full);
    std::snprintf(darker, sizeof darker, "live darker by %.0f %% or more", full);
    legend_swatch(difference_colour(1), brighter);
    ImGui::SameLine(0, 2 * gap);
    legend_swatch(difference_colour(-1), darker);
    ImGui::SameLine(0, 2 * gap);
    legend_swatch(insignificant_difference_colour(), "within the reference's noise");
    const MonteCarloImage& t = r.traced;
    ImGui::Text("%d x %d pixels, %lld passes in %.1f s (%s), noise %.1f %%", t.image.width, t.image.height,
                static_cast<long long>(t.passes), t.seconds, t.stop_reason.c_str(),
                100 * *std::max_element(t.relative_error.begin(), t.relative_error.end()));
    ImGui::Text("live against reference: relative L2 %.1f %%, %.1f %% after brightness x%.2f, PSNR %.1f dB",
                100 * r.difference.relative_l2, 100 * r.difference.scaled_relative_l2, r.difference.scale,
                r.difference.psnr_db);
    ImGui::End();
    return request;
}

}  // namespace waxwork
