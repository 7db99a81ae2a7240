// The last drawn 3D view, kept in a single-sampled framebuffer: frames in which nothing the view shows
// has changed (hovering a panel, a progress bar moving, typing) copy it into the window instead of
// drawing the surface again. Drawing is what costs on a software rasteriser (llvmpipe spends about
// 130 ms on a 1000 x 700 view with 4x MSAA at 100K tets); a copy costs well under a millisecond.
#pragma once

#include "gl/gl_context.h"

#include <Eigen/Core>

namespace waxwork {

// What the picture depends on, compared bit for bit.
struct ViewKey {
    Eigen::Matrix4d view = Eigen::Matrix4d::Zero();
    Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
    int width = 0, height = 0, samples = 0;
    float exposure = 0;
    long long scene_version = -1;  // bumped whenever the render input changes

    friend bool operator==(const ViewKey&, const ViewKey&) = default;
};

class ViewCache {
public:
    explicit ViewCache(const GlApi& gl) : gl_(gl) {}
    ~ViewCache();
    ViewCache(const ViewCache&) = delete;
    ViewCache& operator=(const ViewCache&) = delete;

    bool holds(const ViewKey& key) const { return valid_ && key == key_; }
    // A framebuffer of the key's size to draw into; the cache holds `key` from now on.
    GLuint begin_update(const ViewKey& key);
    void invalidate() { valid_ = false; }
    // Copies the cached view into `target` (0: the window) with its lower-left corner at (x, y).
    void blit(GLuint target, int x, int y) const;

private:
    void release();

    const GlApi& gl_;
    GLuint framebuffer_ = 0;
    GLuint colour_ = 0;
    int width_ = 0, height_ = 0;
    ViewKey key_;
    bool valid_ = false;
};

}  // namespace waxwork
