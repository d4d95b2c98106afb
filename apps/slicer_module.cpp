#include "apps/slicer_module.h"

#include "apps/report/html.h"
#include "mesh/atomic_file.h"

namespace mrsnake::cli {
namespace {

// XML text: the HTML escape serves (&, <, >, quotes).
std::string escaped(const std::string& text) { return reports::escape_html(text); }

std::string element(const std::string& tag, const std::string& text) {
  return "      <" + tag + ">" + escaped(text) + "</" + tag + ">\n";
}

// The executable's head: the fields the schema asks for, in its order.
std::string head(const std::string& title, const std::string& description) {
  return "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<executable>\n"
         "  <category>Segmentation.mrsnake</category>\n"
         "  <title>" +
         escaped(title) +
         "</title>\n"
         "  <description>" +
         escaped(description) +
         "</description>\n"
         "  <version>" MRSNAKE_VERSION
         "</version>\n"
         "  <documentation-url>docs/slicer.md</documentation-url>\n"
         "  <license>GPL-3.0-or-later</license>\n"
         "  <contributor>mrsnake</contributor>\n";
}

// An indexed parameter (image, geometry): Slicer passes it positionally, at `index`.
std::string indexed(const std::string& kind, const std::string& attributes, const std::string& name,
                    const std::string& label, const std::string& description, const std::string& channel, int index) {
  return "    <" + kind + (attributes.empty() ? "" : " " + attributes) + ">\n" + element("name", name) +
         element("label", label) + element("description", description) + element("channel", channel) +
         element("index", std::to_string(index)) + "    </" + kind + ">\n";
}

// A parameter by its long flag (directory, string, integer): `default_value` empty for none.
std::string flagged(const std::string& kind, const std::string& name, const std::string& label,
                    const std::string& description, const std::string& default_value) {
  return "    <" + kind + ">\n" + element("name", name) + element("longflag", name) + element("label", label) +
         element("description", description) + (default_value.empty() ? "" : element("default", default_value)) +
         "    </" + kind + ">\n";
}

std::string group(const std::string& label, const std::string& description, const std::string& parameters) {
  return "  <parameters>\n    <label>" + escaped(label) + "</label>\n    <description>" + escaped(description) +
         "</description>\n" + parameters + "  </parameters>\n";
}

}  // namespace

std::string segment_module_xml() {
  const std::string io =
      indexed("image", "fileExtensions=\".nii.gz,.nrrd\"", "inputVolume", "Image", "The volume to segment", "input",
              0) +
      indexed("image", "type=\"label\" fileExtensions=\".nrrd,.nii.gz\"", "outputLabels", "Label map",
              "Every structure with its reference label value, on the image's grid", "output", 1) +
      indexed("geometry", "type=\"model\" fileExtensions=\".vtk,.vtp\"", "outputSurfaces", "Surfaces",
              "Every structure's final surface, in one model", "output", 2) +
      flagged("directory", "model", "Shape model", "The model folder made by mrsnake build-model", "") +
      flagged("directory", "output", "Result folder",
              "Where the full result goes (report.html, report.json, surfaces/, labels.seg.nrrd); a "
              "temporary folder, removed after the run, when none is given",
              "");
  const std::string options =
      flagged("string", "init", "Initialization",
              "auto, pose, moments, fit, moments+fit, register or register+fit (mrsnake segment --init); empty: "
              "auto, or the options file's",
              "") +
      flagged("string", "force", "External force",
              "auto, profile or edge (mrsnake segment --force); empty: auto, or the options file's", "") +
      flagged("string", "config", "Options file",
              "A JSON file of segmentation options (docs/segmentation.md), or nothing", "");
  return head("mrsnake segment",
              "Segments a volume with a multiresolution shape model: registration, then a coarse-to-fine "
              "snake; a label map, the surfaces, and a verdict per structure in the result folder's report.") +
         group("Input and output", "The volume, the model and the results", io) +
         group("Options", "Every default follows the structure's size and the image's voxels", options) +
         "</executable>\n";
}

std::string build_model_module_xml() {
  const std::string io =
      indexed("image", "type=\"label\" fileExtensions=\".nii.gz,.nrrd\"", "referenceLabels", "Reference labels",
              "The label map the model is built from", "input", 0) +
      indexed("image", "fileExtensions=\".nii.gz,.nrrd\"", "referenceImage", "Reference image",
              "The image of the labels: the appearance and the registration crop", "input", 1) +
      flagged("string", "label", "Label values", "The structures: values as 1,3,7, or all", "all") +
      flagged("directory", "output", "Model folder", "Where the model goes (replaced if it is already a model)", "");
  return head("mrsnake build-model",
              "Builds a multiresolution shape model of one or more structures of a reference label map: "
              "marching cubes, semi-regular remeshing, lifting wavelets, appearance profiles.") +
         group("Input and output", "The reference and the model", io) + "</executable>\n";
}

void write_return_parameters(const std::string& path, const std::vector<std::pair<std::string, std::string>>& values) {
  std::string text;
  for (const auto& [name, value] : values) text += name + " = " + value + "\n";
  write_text_file_atomically(path, text);
}

}  // namespace mrsnake::cli
