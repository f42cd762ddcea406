// Sets or clears an environment variable for a scope, then restores it: for the tests of what
// reads the environment at each use, Mesa's disk cache (which Mesa reads whenever a device is made)
// and libcurl's proxies. The library's own settings go through options (gpu/environment.h).
#pragma once

#include <cstdlib>
#include <optional>
#include <string>

namespace sdfcsg::test {

class ScopedEnv {
  public:
    // value null: the variable is unset for the scope.
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value)
            ::setenv(name, value, 1);
        else
            ::unsetenv(name);
    }
    ScopedEnv(const char* name, const std::string& value) : ScopedEnv(name, value.c_str()) {}
    ~ScopedEnv() {
        if (old_)
            ::setenv(name_, old_->c_str(), 1);
        else
            ::unsetenv(name_);
    }
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

  private:
    const char* name_;
    std::optional<std::string> old_;
};

} // namespace sdfcsg::test
