#pragma once
// A dense 3D array of doubles, x fastest: index (i, j, k) -> i + nx*(j + ny*k).
// In FFTW's row-major terms its dimensions are {nz, ny, nx}.
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace immerse {

class Array3 {
 public:
  Array3() = default;
  Array3(int nx, int ny, int nz, double value = 0.0)
      : n_{nx, ny, nz}, data_(static_cast<std::size_t>(nx) * ny * nz, value) {}

  int nx() const { return n_[0]; }
  int ny() const { return n_[1]; }
  int nz() const { return n_[2]; }
  int n(int axis) const { return n_[axis]; }
  const std::array<int, 3>& shape() const { return n_; }
  std::size_t size() const { return data_.size(); }

  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(n_[0]) * (static_cast<std::size_t>(j) +
                                                                            static_cast<std::size_t>(n_[1]) * k);
  }
  double& operator()(int i, int j, int k) { return data_[index(i, j, k)]; }
  double operator()(int i, int j, int k) const { return data_[index(i, j, k)]; }
  double& operator[](std::size_t idx) { return data_[idx]; }
  double operator[](std::size_t idx) const { return data_[idx]; }

  double* data() { return data_.data(); }
  const double* data() const { return data_.data(); }
  std::vector<double>& values() { return data_; }
  const std::vector<double>& values() const { return data_; }

  void fill(double v) { std::fill(data_.begin(), data_.end(), v); }

 private:
  std::array<int, 3> n_{0, 0, 0};
  std::vector<double> data_;
};

}  // namespace immerse
