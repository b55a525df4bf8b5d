#include "evcorner/io/dynamic_library.hpp"

#include <dlfcn.h>
#include <sys/auxv.h>
#include <fmt/format.h>

#include <stdexcept>

namespace evcorner::io {

DynamicLibrary::DynamicLibrary(const std::string& what, const std::vector<std::string>& names) : what_(what) {
    std::string tried;
    for (const auto& n : names) {
        if (n.empty()) continue;
        if (void* h = ::dlopen(n.c_str(), RTLD_NOW | RTLD_GLOBAL)) {
            handle_ = h;
            name_ = n;
            return;
        }
        const char* err = ::dlerror();
        tried += fmt::format("{}{}", tried.empty() ? "" : "; ", err ? err : n);
    }
    throw std::runtime_error(fmt::format("cannot load {} ({})", what, tried.empty() ? "no library name" : tried));
}

void* DynamicLibrary::address(const char* symbol) const {
    ::dlerror();
    void* p = ::dlsym(handle_, symbol);
    if (p == nullptr) {
        const char* err = ::dlerror();
        throw std::runtime_error(fmt::format("{} ({}) has no symbol {}{}{}", what_, name_, symbol, err ? ": " : "",
                                             err ? err : ""));
    }
    return p;
}

void* DynamicLibrary::variable_address(const char* symbol) const {
    void* own = address(symbol);
    void* first = ::dlsym(RTLD_DEFAULT, symbol);  // the program, then the libraries in load order
    if (first == nullptr || first == own) return own;
    Dl_info found{}, program{};
    const auto* phdr = reinterpret_cast<const void*>(::getauxval(AT_PHDR));  // inside the program's image
    if (phdr != nullptr && ::dladdr(first, &found) != 0 && ::dladdr(phdr, &program) != 0 &&
        found.dli_fbase == program.dli_fbase)
        return first;
    return own;
}

}  // namespace evcorner::io
