#include "bench/studies/environment_study.h"

#include "base/timing.h"
#include "solver/environment_transfer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

namespace waxwork {

EnvironmentLight studio_environment(int order) {
    constexpr int kWidth = 512, kHeight = 256;
    std::vector<Rgb> pixels(static_cast<size_t>(kWidth) * kHeight);
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const double longitude = 360.0 * (x + 0.5) / kWidth - 180;  // 0 along -z, 90 along +x
            const double latitude = 90 - 180.0 * (y + 0.5) / kHeight;
            const bool softbox = std::abs(longitude - 135) < 20 && std::abs(latitude - 30) < 12.5;
            pixels[static_cast<size_t>(y) * kWidth + x] = softbox ? Rgb{40, 34, 28} : Rgb{0.15, 0.15, 0.17};
        }
    }
    return environment_light(std::make_shared<const EnvironmentMap>(kWidth, kHeight, std::move(pixels), "studio"), order);
}

TransferAccuracy study_transfer_accuracy(const BoundarySurface& surface, const TriangleBvh& bvh,
                                         const EnvironmentLight& environment, const std::string& name,
                                         std::span<const int> orders, int reference_samples) {
    TransferAccuracy study;
    study.environment = name;
    study.reference_samples = reference_samples;
    auto start = std::chrono::steady_clock::now();
    const std::vector<Rgb> reference = sampled_environment_light(surface, bvh, true, environment, reference_samples);
    study.reference_ms = milliseconds_since(start);
    double reference_norm = 0;
    for (const Rgb& q : reference)
        for (const double c : q) reference_norm += c * c;
    const double peak = std::max_element(reference.begin(), reference.end(),
                                         [](const Rgb& a, const Rgb& b) { return a[1] < b[1]; })->at(1);
    for (const int order : orders) {
        EnvironmentLight projected = environment_light(environment.map, order);
        projected.rotation_degrees = environment.rotation_degrees;
        projected.intensity = environment.intensity;
        TransferSettings settings;
        settings.order = order;
        TransferAccuracyRow row;
        row.order = order;
        start = std::chrono::steady_clock::now();
        const EnvironmentTransfer transfer = compute_environment_transfer(surface, bvh, settings);
        row.transfer_ms = milliseconds_since(start);
        projected.rotation_degrees += 1;  // a turn, then back: the relight the editor does per frame
        start = std::chrono::steady_clock::now();
        std::vector<Rgb> q = apply_environment_transfer(transfer, projected);
        row.relight_ms = milliseconds_since(start);
        projected.rotation_degrees -= 1;
        q = apply_environment_transfer(transfer, projected);
        double difference = 0;
        std::vector<double> relative;
        for (size_t s = 0; s < q.size(); ++s) {
            for (int c = 0; c < 3; ++c) difference += (q[s][c] - reference[s][c]) * (q[s][c] - reference[s][c]);
            // Vertices lit at least 1% of the brightest: relative errors of near-black ones say nothing.
            if (reference[s][1] > 0.01 * peak) relative.push_back(std::abs(q[s][1] - reference[s][1]) / reference[s][1]);
        }
        row.relative_l2 = reference_norm > 0 ? std::sqrt(difference / reference_norm) : 0;
        if (!relative.empty()) {
            std::nth_element(relative.begin(), relative.begin() + relative.size() / 2, relative.end());
            row.median_relative = relative[relative.size() / 2];
        }
        study.rows.push_back(row);
    }
    return study;
}

nlohmann::ordered_json to_json(const TransferAccuracy& study) {
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (const TransferAccuracyRow& r : study.rows)
        rows.push_back({{"order", r.order},
                        {"coefficients", (r.order + 1) * (r.order + 1)},
                        {"transfer_ms", r.transfer_ms},
                        {"relight_ms", r.relight_ms},
                        {"relative_l2", r.relative_l2},
                        {"median_relative", r.median_relative}});
    return {{"environment", study.environment},
            {"reference_samples", study.reference_samples},
            {"reference_ms", study.reference_ms},
            {"rows", rows}};
}

}  // namespace waxwork
