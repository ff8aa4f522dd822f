#pragma once

// Private to src/core/io: the URDF reader parses a large file in two halves on two threads through it.

#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include <pugixml.hpp>

namespace mobility_analysis {
namespace io_detail {

/**
 * @brief A file parsed as two documents, cut before a top-level element near its middle: the first half
 *        closed with the root's end tag, the second opened with its start tag. Both parse in place in one
 *        buffer, each on its own thread.
 *
 * Why it is safe: the halves are taken only when each parses without error, the first is UTF-8 with one
 * element at its top (the root, named as asked, closed by the end tag written at the cut) and the second has
 * the root written at the cut and nothing but comments and processing instructions after it. The first then
 * holds, in order, every child the root had before the cut, and the second every child after it, as the
 * whole document would: an end tag at the cut closes the root only where the cut is directly inside it (not
 * in a comment, CDATA, an attribute or a nested element, where the first half does not parse), and the
 * second half starts its root where the whole one went on. Anything else gives nothing, and the caller
 * parses the file whole, for the same answer and the same error as before.
 */
struct XmlHalves {
  std::string text;  ///< Both halves' text, the seam written in; the documents point into it.
  pugi::xml_document first, second;
  size_t cut = 0;  ///< The byte of the file the second half's first element starts at.
};

/**
 * @brief Reads the regular file at @p path and parses it in two halves (XmlHalves), cut at the first element
 *        from byte @p cutFrom on that begins a line at the indentation of the root's first child (within 64
 *        KiB of it).
 * @param[in] options pugixml's parse options for both halves.
 * @param[in] root the root element's name ("robot").
 * @param[in] minBytes the smallest file cut (a smaller one gives nothing).
 * @param[in] cutFrom where the cut is looked for; by default the middle of the file.
 * @return The halves, or nothing when the file cannot be read that way or its halves are not taken (then
 *         parse it whole).
 */
std::unique_ptr<XmlHalves> parseInHalves(const std::string& path, unsigned options, const char* root,
                                         size_t minBytes, std::optional<size_t> cutFrom = std::nullopt);

}  // namespace io_detail
}  // namespace mobility_analysis
