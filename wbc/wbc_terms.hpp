#pragma once
// Problem 1 as data (TSID style): a list of weighted least-squares tasks and a list of linear constraints,
// each refreshed every tick by its own update function and assembled into one pre-sized QpProblem.
// Storage is fixed-capacity Eigen (no heap use per tick); names and update functions are set up once.
#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>

namespace mft::wbc {

// Decision variables x = [qdd (11) | f_c (4) | eps (12)] (paper: 27).
constexpr int kNqdd = 11;
constexpr int kNfc = 4;
constexpr int kNeps = 12;
constexpr int kNx = kNqdd + kNfc + kNeps;
enum class VarBlock { Qdd, Fc, Eps };
constexpr int blockOffset(VarBlock b) { return b == VarBlock::Qdd ? 0 : (b == VarBlock::Fc ? kNqdd : kNqdd + kNfc); }
constexpr int blockSize(VarBlock b) { return b == VarBlock::Qdd ? kNqdd : (b == VarBlock::Fc ? kNfc : kNeps); }
const char* toString(VarBlock b);

using VectorX = Eigen::Matrix<double, kNx, 1>;

struct TickContext;  // defined in wbc_formulation.hpp

// cost = weight * || A x_block - b ||^2 over one variable block. Tasks touching f_c or eps must keep their
// part of H diagonal (identity-like A) or the assembler drops the block-diagonal hint to the solver.
constexpr int kMaxTaskRows = 12;
using TaskMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxTaskRows, kNeps>;
using TaskVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxTaskRows, 1>;

struct Task {
  std::string name;
  VarBlock block = VarBlock::Qdd;
  double weight = 0.0;  // may be changed by update (e.g. swing vs support foot)
  TaskMatrix A;         // rows x blockSize(block)
  TaskVector b;
  std::function<void(const TickContext&, Task*)> update;
  double residual = 0.0;  // || A x - b || at the last solution (diagnostics)

  Task(std::string name_, VarBlock block_, int rows, double weight_,
       std::function<void(const TickContext&, Task*)> update_)
      : name(std::move(name_)), block(block_), weight(weight_), A(TaskMatrix::Zero(rows, blockSize(block_))),
        b(TaskVector::Zero(rows)), update(std::move(update_)) {}
  int rows() const { return static_cast<int>(A.rows()); }
};

// Equality: A x = lower (upper unused). Inequality: lower <= A x <= upper, +-inf for a missing side.
constexpr int kMaxConstraintRows = 12;
using ConstraintMatrix = Eigen::Matrix<double, Eigen::Dynamic, kNx, Eigen::RowMajor, kMaxConstraintRows, kNx>;
using ConstraintVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxConstraintRows, 1>;

struct Constraint {
  enum class Type { Equality, Inequality };
  std::string name;  // WBCQP row block name: "eq_*" or "in_*"
  Type type = Type::Inequality;
  ConstraintMatrix A;
  ConstraintVector lower, upper;
  std::function<void(const TickContext&, Constraint*)> update;
  int row_offset = 0;  // first row in Aeq or Ain, set by the layout

  Constraint(std::string name_, Type type_, int rows, std::function<void(const TickContext&, Constraint*)> update_)
      : name(std::move(name_)), type(type_), A(ConstraintMatrix::Zero(rows, kNx)),
        lower(ConstraintVector::Zero(rows)), upper(ConstraintVector::Zero(rows)), update(std::move(update_)) {}
  int rows() const { return static_cast<int>(A.rows()); }
};

// Simple bounds lb <= x <= ub (lb == ub fixes a variable).
struct VariableBounds {
  VectorX lb = VectorX::Zero();
  VectorX ub = VectorX::Zero();
};

}  // namespace mft::wbc
