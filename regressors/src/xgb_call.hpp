#pragma once
// Every xgboost C API call goes through DICESTACK_XGB, which throws with the call's text and
// XGBGetLastError(); handles live in RAII holders (STYLE 9).
#include <memory>
#include <string>

#include <xgboost/c_api.h>

#include <dicestack/core/error.hpp>

namespace dicestack::detail {

inline void check_xgb(int status, const char* call) {
  if (status != 0) throw InputError(std::string("gbt: ") + call + " failed: " + XGBGetLastError());
}

struct DMatrixFree {
  void operator()(void* h) const { XGDMatrixFree(h); }
};
struct BoosterFree {
  void operator()(void* h) const { XGBoosterFree(h); }
};
using DMatrixPtr = std::unique_ptr<void, DMatrixFree>;
using BoosterPtr = std::unique_ptr<void, BoosterFree>;

}  // namespace dicestack::detail

#define DICESTACK_XGB(call) ::dicestack::detail::check_xgb((call), #call)
