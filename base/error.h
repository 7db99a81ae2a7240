// Typed errors shared by every Waxwork library.
//
// Every failure a user can cause (a broken file, an absurd parameter) is reported by throwing one of
// these; the command line catches them and prints what() as its one-line message. what() always names
// the file (when there is one) and the problem, e.g. "bad_cow.obj: 1 non-manifold vertex (vertex 17)".
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

namespace waxwork {

// Base of every Waxwork error.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A file could not be read or written, or its content is malformed. what() is "PATH: PROBLEM".
class FileError : public Error {
public:
    FileError(std::string path, std::string problem)
        : Error(path + ": " + problem), path_(std::move(path)), problem_(std::move(problem)) {}
    const std::string& path() const { return path_; }
    const std::string& problem() const { return problem_; }

private:
    std::string path_;
    std::string problem_;
};

// Geometry that violates a requirement: an open or self-intersecting surface, an inverted tet.
class InvalidMeshError : public Error {
public:
    using Error::Error;
};

// A parameter outside its meaningful range (negative edge length, NaN coefficient, ...).
class InvalidArgumentError : public Error {
public:
    using Error::Error;
};

// An algorithm failed on valid input (a mesher gave up, a solver broke down beyond recovery).
class AlgorithmError : public Error {
public:
    using Error::Error;
};

// A number in a message, as %g: 1e308 prints as such rather than as 309 digits, 0.001 not as 0.001000.
inline std::string number_text(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return text;
}

// Runs `work` and gives its argument, parameter and algorithm errors "context: " (a file name) before
// their message, keeping their type: for callers that know the file a library call works on.
template <typename Work>
decltype(auto) naming_context(const std::string& context, Work&& work) {
    try {
        return work();
    } catch (const InvalidArgumentError& error) {
        throw InvalidArgumentError(context + ": " + error.what());
    } catch (const InvalidMeshError& error) {
        throw InvalidMeshError(context + ": " + error.what());
    } catch (const AlgorithmError& error) {
        throw AlgorithmError(context + ": " + error.what());
    }
}

}  // namespace waxwork
