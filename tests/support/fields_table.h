// Reading the table `render --fields` writes (scene/fields_csv.h), for the tests that compare with it.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace waxwork::testing {

struct FieldRow {
    double x, y, z;
    bool boundary;
    std::array<double, 3> q, phi, lo;
    std::array<double, 3> phi_err;  // render --method mc only (else zero)
};

struct Fields {
    std::string header;
    std::vector<FieldRow> rows;
    bool all_finite = true;
};

inline Fields read_fields(const std::filesystem::path& path) {
    std::ifstream in(path);
    Fields fields;
    std::getline(in, fields.header);
    std::string line;
    while (std::getline(in, line)) {
        std::vector<double> v;
        std::stringstream s(line);
        std::string item;
        while (std::getline(s, item, ',')) {
            // strtod accepts "nan" and "inf", which is what the test must catch.
            v.push_back(std::strtod(item.c_str(), nullptr));
            if (!std::isfinite(v.back())) fields.all_finite = false;
        }
        if (v.size() != 13 && v.size() != 16) {
            ADD_FAILURE() << "row with " << v.size() << " columns: " << line;
            continue;
        }
        std::array<double, 3> phi_err{};
        if (v.size() == 16) phi_err = {v[13], v[14], v[15]};
        fields.rows.push_back(
            {v[0], v[1], v[2], v[3] != 0, {v[4], v[5], v[6]}, {v[7], v[8], v[9]}, {v[10], v[11], v[12]}, phi_err});
    }
    return fields;
}

}  // namespace waxwork::testing
