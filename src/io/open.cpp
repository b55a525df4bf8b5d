#include "evcorner/io/open.hpp"

#include "evcorner/error.hpp"
#include "evcorner/io/text_reader.hpp"

namespace evcorner::io {

std::unique_ptr<EventReader> open_event_reader(const std::string& path, ReaderOptions options,
                                               std::string_view format) {
    if (format == "auto" || format == "ecd-text" || format == "text") {
        if (!options.sensor) options.sensor = kDavis240;
        return std::make_unique<TextReader>(path, options);
    }
    throw InputError(path == "-" ? "<stdin>" : path,
                     "unknown input format '" + std::string(format) + "'");
}

}  // namespace evcorner::io
