#pragma once
/// Symbols of tsi::core and of plugin entry points are hidden unless marked with TSI_API:
/// the library exports exactly its public interface.
#define TSI_API __attribute__((visibility("default")))
