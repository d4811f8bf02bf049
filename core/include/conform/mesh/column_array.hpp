// Per-vertex columns with spare capacity, for the fields of SkinnedMesh.
//
// Every topology change appends vertices, and Eigen's Matrix has no capacity: its
// conservativeResize copies every column each time, O(#V) per change. ColumnArray is an
// Eigen::Map (so every Eigen expression, col(), row(), operator(), data(), setZero(), … works on
// it as on a matrix) over storage that grows geometrically (×1.5), so appending k columns costs
// amortized O(k); a copy or an assignment leaves room for about 1/8 more columns, so that the
// first changes to a copied or imported mesh do not copy it again.
//
// Differences from Eigen::Matrix: assignment and resize() change the size (and keep the
// spare capacity); new columns after resize() or conservativeResize() are unspecified, as in
// Eigen.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <new>
#include <stdexcept>

namespace conform::mesh {

template <class Scalar, int Rows>
class ColumnArray : public Eigen::Map<Eigen::Matrix<Scalar, Rows, Eigen::Dynamic>> {
 public:
  using Matrix = Eigen::Matrix<Scalar, Rows, Eigen::Dynamic>;
  using Base = Eigen::Map<Matrix>;

  ColumnArray() : Base(nullptr, Rows, 0) {}
  ColumnArray(Eigen::Index rows, Eigen::Index cols) : Base(nullptr, Rows, 0) { resize(rows, cols); }
  ColumnArray(const ColumnArray& other) : Base(nullptr, Rows, 0) { copy_from(other); }
  ColumnArray(ColumnArray&& other) noexcept : Base(nullptr, Rows, 0) { take(other); }
  template <class Derived>
  ColumnArray(const Eigen::DenseBase<Derived>& expression) : Base(nullptr, Rows, 0) {
    assign(expression);
  }

  ColumnArray& operator=(const ColumnArray& other) {
    if (this != &other) copy_from(other);
    return *this;
  }
  ColumnArray& operator=(ColumnArray&& other) noexcept {
    if (this != &other) take(other);
    return *this;
  }
  template <class Derived>
  ColumnArray& operator=(const Eigen::DenseBase<Derived>& expression) {
    assign(expression);
    return *this;
  }

  /// Sets the size; the contents are unspecified (Eigen's resize).
  void resize(Eigen::Index rows, Eigen::Index cols) { conservativeResize(rows, cols); }
  /// Sets the size keeping the first min(old, new) columns; new columns are unspecified.
  void conservativeResize(Eigen::Index rows, Eigen::Index cols) {
    if (rows != Rows || cols < 0) throw std::invalid_argument("ColumnArray: bad shape");
    if (cols > capacity_) reallocate(std::max(cols, capacity_ + capacity_ / 2));
    seat(cols);
  }
  using Base::setZero;
  /// Resizes, then sets every coefficient to zero (Eigen's setZero(rows, cols)).
  ColumnArray& setZero(Eigen::Index rows, Eigen::Index cols) {
    resize(rows, cols);
    Base::setZero();
    return *this;
  }
  /// Room for `cols` columns without reallocating.
  void reserve(Eigen::Index cols) {
    if (cols > capacity_) reallocate(cols);
  }
  Eigen::Index capacity() const { return capacity_; }

 private:
  // A filled array gets room for about 1/8 more columns, so that the first changes after a
  // copy or an import do not reallocate; an empty one (no UVs, say) allocates nothing.
  static Eigen::Index headroom(Eigen::Index cols) { return cols > 0 ? cols + cols / 8 + 16 : 0; }
  // Points the Map at the storage (placement new is Eigen's documented way to re-seat a Map).
  void seat(Eigen::Index cols) { new (static_cast<Base*>(this)) Base(storage_.data(), Rows, cols); }
  // New storage for `capacity` columns (an Eigen matrix: not zeroed, new columns are
  // unspecified), keeping the used ones.
  void reallocate(Eigen::Index capacity) {
    Matrix bigger(Rows, capacity);
    bigger.leftCols(this->cols()) = static_cast<const Base&>(*this);
    storage_.swap(bigger);
    capacity_ = capacity;
    seat(this->cols());
  }
  // Makes this `cols` columns long with the values at `values` (column-major, Rows × cols).
  void fill(const Scalar* values, Eigen::Index cols) {
    if (cols > capacity_) {
      storage_.resize(Rows, headroom(cols));
      capacity_ = headroom(cols);
    }
    storage_.leftCols(cols) = Eigen::Map<const Matrix>(values, Rows, cols);
    seat(cols);
  }
  void copy_from(const ColumnArray& other) { fill(other.data(), other.cols()); }
  void take(ColumnArray& other) {
    storage_.swap(other.storage_);
    other.storage_.resize(Rows, 0);
    capacity_ = other.capacity_;
    seat(other.cols());
    other.capacity_ = 0;
    other.seat(0);
  }
  template <class Derived>
  void assign(const Eigen::DenseBase<Derived>& expression) {
    if (expression.rows() != Rows) throw std::invalid_argument("ColumnArray: bad shape");
    const Matrix value = expression;  // evaluated first: the expression may read this array
    fill(value.data(), value.cols());
  }

  Matrix storage_;  // Rows × capacity_
  Eigen::Index capacity_ = 0;
};

}  // namespace conform::mesh
