#pragma once
// What the API tests ask of a call that must fail: the kind of its api::Error.

#include <gtest/gtest.h>

#include <functional>

#include "octray/octray.h"

namespace octray::api::testing {

// The kind of the api::Error that f throws; a test failure (and ErrorKind::io) if it
// throws none.
inline ErrorKind kind_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.kind();
    }
    ADD_FAILURE() << "no api::Error thrown";
    return ErrorKind::io;
}

}  // namespace octray::api::testing
