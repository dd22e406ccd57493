// Master-side process image (protocol-facts.md §F).
#include "pbvbus/dp/master_image.hpp"

#include <algorithm>
#include <array>

namespace pbvbus::dp {

std::string_view to_string(ImageAccess a) {
  switch (a) {
    case ImageAccess::Ok: return "ok";
    case ImageAccess::NoSuchModule: return "no such module";
    case ImageAccess::WrongLength: return "wrong length";
  }
  return "?";
}

MasterImage::MasterImage(const SlaveLayout& layout)
    : m_layout(layout.modules), m_output_len(layout.outputs), m_inputs(layout.inputs) {
  m_out.reserve(m_layout.size());
  for (const auto& m : m_layout) m_out.push_back(std::make_unique<ConsistentBuffer>(m.out_len));
}

ImageAccess MasterImage::read_inputs(std::size_t module, std::span<std::uint8_t> out) const {
  if (module >= m_layout.size()) return ImageAccess::NoSuchModule;
  const ModuleLayout& m = m_layout[module];
  if (out.size() != m.in_len) return ImageAccess::WrongLength;
  // The whole telegram is one seqlock unit: read it all, then cut the module out.
  std::array<std::uint8_t, kMaxIoLen> buf{};
  m_inputs.read({buf.data(), m_inputs.size()});
  std::copy_n(buf.begin() + static_cast<std::ptrdiff_t>(m.in_offset), m.in_len, out.begin());
  return ImageAccess::Ok;
}

ImageAccess MasterImage::read_all_inputs(std::span<std::uint8_t> out) const {
  if (out.size() != m_inputs.size()) return ImageAccess::WrongLength;
  m_inputs.read(out);
  return ImageAccess::Ok;
}

ImageAccess MasterImage::write_outputs(std::size_t module, std::span<const std::uint8_t> data) {
  if (module >= m_layout.size()) return ImageAccess::NoSuchModule;
  if (data.size() != m_layout[module].out_len) return ImageAccess::WrongLength;
  m_out[module]->write(data);
  return ImageAccess::Ok;
}

ImageAccess MasterImage::read_outputs(std::size_t module, std::span<std::uint8_t> out) const {
  if (module >= m_layout.size()) return ImageAccess::NoSuchModule;
  if (out.size() != m_layout[module].out_len) return ImageAccess::WrongLength;
  m_out[module]->read(out);
  return ImageAccess::Ok;
}

void MasterImage::snapshot_outputs(std::span<std::uint8_t> telegram) const {
  for (std::size_t m = 0; m < m_layout.size(); ++m)
    m_out[m]->read(telegram.subspan(m_layout[m].out_offset, m_layout[m].out_len));
}

void MasterImage::publish_inputs(std::span<const std::uint8_t> telegram) {
  m_inputs.write(telegram);
}

}  // namespace pbvbus::dp
