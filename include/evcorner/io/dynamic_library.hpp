#pragma once
// A shared library opened on first use (dlopen) instead of linked: libhdf5 and libmatio.
// With their dependencies (libcurl, GnuTLS, Kerberos, LDAP, ...) they were 32 of the 46
// shared objects that every evcorner process (and `import evcorner`) loaded and relocated
// at start, about half of a short run's CPU time (docs/performance.md, "Process start"),
// for two file formats most runs never touch.
//
// A reader or writer of those formats lists the functions it calls in a table (one
// function-pointer field per function, filled by `symbol`), and declares each function
// again in its own namespace under its own name: a constexpr pointer to a function with
// the same signature that calls through the table (Forwarder below). Unqualified calls,
// and the library's macros that expand to unqualified names, find these before the
// library header's global declarations, so the code reads as plain library calls. A name
// left out is an undefined reference at link time (the library is not linked), never a
// silent one.
// Internal: not installed.

#include <stdexcept>
#include <string>
#include <vector>

namespace evcorner::io {

class DynamicLibrary {
public:
    /// Opens the first of `names` (sonames or paths) that loads, with RTLD_NOW |
    /// RTLD_GLOBAL (plug-ins the library loads itself may need its symbols). Throws
    /// std::runtime_error naming `what` and each name's dlerror() when none loads.
    DynamicLibrary(const std::string& what, const std::vector<std::string>& names);
    DynamicLibrary(const DynamicLibrary&) = delete;
    DynamicLibrary& operator=(const DynamicLibrary&) = delete;
    /// Never closes the library: its state (open files, registered filters, atexit
    /// handlers) lives as long as the process.
    ~DynamicLibrary() = default;

    /// The address of `symbol`; throws std::runtime_error naming it when absent.
    [[nodiscard]] void* address(const char* symbol) const;
    /// The address of the variable `symbol` as the process uses it: a program linked with
    /// the library itself holds copies of the library's variables (copy relocations), and
    /// the library then uses those, so the program's copy where it has one, else
    /// `address(symbol)`.
    [[nodiscard]] void* variable_address(const char* symbol) const;
    /// `address` as a pointer of the given type: `lib.symbol(fn, "H5Fopen")`.
    template <class T>
    void symbol(T*& out, const char* name) const {
        out = reinterpret_cast<T*>(address(name));
    }
    /// The name (of `names`) that was loaded.
    [[nodiscard]] const std::string& loaded_name() const noexcept { return name_; }

private:
    void* handle_ = nullptr;
    std::string what_, name_;
};

/// Forwarder<decltype(&::fn)>::call<Table, &Table::fn>: a function with fn's signature that
/// calls fn through Table::get(), the table of the loaded library.
template <class Fn>
struct Forwarder;
template <class R, class... A>
struct Forwarder<R (*)(A...)> {
    template <class Table, auto Member>
    static R call(A... a) {
        return (Table::get().*Member)(a...);
    }
};

/// Loads Table (Table::get()) where it is not loaded yet; a failure becomes an Error
/// (InputError, OutputError) naming `file`, the file that needed the library.
template <class Table, class Error>
void load_for(const std::string& file) {
    try {
        (void)Table::get();
    } catch (const std::runtime_error& e) {
        throw Error(file, e.what());
    }
}

}  // namespace evcorner::io
