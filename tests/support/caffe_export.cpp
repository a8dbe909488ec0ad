#include "tests/support/caffe_export.hpp"

#include "autograd/tensor.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace nn {

namespace {

// Minimal protobuf encoder for the few caffe.proto fields we write.
struct Proto {
  std::string buf;
  void varint(uint64_t v) {
    while (v >= 0x80) {
      buf.push_back(static_cast<char>((v & 0x7f) | 0x80));
      v >>= 7;
    }
    buf.push_back(static_cast<char>(v));
  }
  void tag(int field, int wire) { varint((static_cast<uint64_t>(field) << 3) | static_cast<uint64_t>(wire)); }
  void bytes(int field, const std::string& s) {  // length-delimited (string or sub-message)
    tag(field, 2);
    varint(s.size());
    buf += s;
  }
  void packed_floats(int field, const std::vector<float>& v) {
    std::string raw(v.size() * 4, '\0');
    if (!v.empty()) std::memcpy(&raw[0], v.data(), raw.size());  // little-endian host
    bytes(field, raw);
  }
  void packed_varints(int field, const std::vector<int64_t>& v) {
    Proto p;
    for (int64_t x : v) p.varint(static_cast<uint64_t>(x));
    bytes(field, p.buf);
  }
};

// BlobProto { shape = 7: BlobShape { dim = 1 (packed int64) }, data = 5 (packed float) }
std::string blob(const std::vector<int64_t>& shape, const std::vector<float>& data) {
  Proto shp;
  shp.packed_varints(1, shape);
  Proto b;
  b.bytes(7, shp.buf);
  b.packed_floats(5, data);
  return b.buf;
}

void write_atomic(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw ag::Error("write_vgg_caffe: cannot open '" + tmp + "' for writing");
    f.write(content.data(), static_cast<std::streamsize>(content.size()));
    f.flush();
    if (!f) {
      std::remove(tmp.c_str());
      throw ag::Error("write_vgg_caffe: write failed on '" + tmp + "'");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw ag::Error("write_vgg_caffe: cannot rename '" + tmp + "' to '" + path + "'");
  }
}

}  // namespace

void write_vgg_caffe(const VggWeights& w, const std::string& prototxt_path, const std::string& caffemodel_path,
                     int64_t height, int64_t width, bool avg_pool) {
  if (w.convs.empty() || w.convs.size() > 16) throw ag::Error("write_vgg_caffe: need 1 to 16 convolutions");
  const auto& names = vgg19_conv_names();
  std::ostringstream txt;
  txt << "name: \"vgg19_gdsr_export\"\n"
      << "layer { name: \"data\" type: \"Input\" top: \"data\" input_param { shape { dim: 1 dim: 3 dim: " << height
      << " dim: " << width << " } } }\n";
  Proto net;
  net.bytes(1, "vgg19_gdsr_export");
  std::string bottom = "data";
  for (size_t i = 0; i < w.convs.size(); ++i) {
    const VggConv& c = w.convs[i];
    if (static_cast<int64_t>(c.weight.size()) != c.out * c.in * 9 || static_cast<int64_t>(c.bias.size()) != c.out)
      throw ag::Error("write_vgg_caffe: " + names[i] + " has inconsistent weight sizes");
    const std::string conv = names[i], relu = "relu" + names[i].substr(4);
    txt << "layer { name: \"" << conv << "\" type: \"Convolution\" bottom: \"" << bottom << "\" top: \"" << conv
        << "\" convolution_param { num_output: " << c.out << " kernel_size: 3 pad: 1 stride: 1 } }\n"
        << "layer { name: \"" << relu << "\" type: \"ReLU\" bottom: \"" << conv << "\" top: \"" << conv << "\" }\n";
    bottom = conv;
    // LayerParameter { name = 1, type = 2, blobs = 7 }, NetParameter.layer = 100
    Proto layer;
    layer.bytes(1, conv);
    layer.bytes(2, "Convolution");
    layer.bytes(7, blob({c.out, c.in, 3, 3}, c.weight));
    layer.bytes(7, blob({c.out}, c.bias));
    net.bytes(100, layer.buf);
    const bool pool = (i == 1 || i == 3 || i == 7 || i == 11) && i + 1 < w.convs.size();
    if (pool) {
      const std::string p = "pool" + std::to_string(i == 1 ? 1 : i == 3 ? 2 : i == 7 ? 3 : 4);
      txt << "layer { name: \"" << p << "\" type: \"Pooling\" bottom: \"" << bottom << "\" top: \"" << p
          << "\" pooling_param { pool: " << (avg_pool ? "AVE" : "MAX") << " kernel_size: 2 stride: 2 } }\n";
      bottom = p;
    }
  }
  write_atomic(prototxt_path, txt.str());
  write_atomic(caffemodel_path, net.buf);
}

}  // namespace nn
