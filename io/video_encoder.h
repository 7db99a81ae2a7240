// A video of numbered frames through ffmpeg when it is installed: the turntable's MP4. No library of
// Debian 12 writes H.264 as simply as the ffmpeg program does, and the frames are PNGs already, so
// the encoder is run as a child process; without it the frames are the result.
#pragma once

#include <filesystem>
#include <string>

namespace waxwork {

// The executable `name` found on the PATH, or "" when there is none.
std::string find_on_path(const std::string& name);

// Runs `ffmpeg` on DIR/frame_%04d.png: H.264 in yuv420p (what players expect; width and height padded
// to even numbers as the encoder needs), `fps` frames a second, into `mp4`. Its own output goes to
// stderr only on failure (-loglevel error). Returns whether it succeeded.
bool encode_mp4(const std::string& ffmpeg, const std::filesystem::path& dir, const std::filesystem::path& mp4, double fps);

}  // namespace waxwork
