#pragma once
#include <stdexcept>
#include <string>

#include "tsi/export.hpp"

namespace tsi {

/// Every error tsi reports is a tsi::Error; library code never calls exit().
class TSI_API Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad input: names the offending field (a config path such as "model.eps"), the value
/// and what was expected. what() reads "FIELD: MESSAGE".
class TSI_API ConfigError : public Error {
 public:
  ConfigError(std::string field, const std::string& message)
      : Error(field.empty() ? message : field + ": " + message), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

/// An output that could not be written (a full disk, a file size limit, a directory that went
/// away): what() names the file and the system's reason. The runner exits with 3 on it.
class TSI_API IoError : public Error {
 public:
  using Error::Error;
};

/// A plugin that could not be loaded or registered.
class TSI_API PluginError : public Error {
 public:
  using Error::Error;
};

}  // namespace tsi
