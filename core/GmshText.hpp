#pragma once
/// \file
/// \brief The parts of reading a Gmsh MSH 4.1 ASCII file that every mesh reader shares: a lexer
/// that knows the line of each token (for messages "<file>:<line>: ..."), the sections $MeshFormat,
/// $PhysicalNames, $Entities and $Nodes, and the block structure of $Elements. A reader (hexahedral
/// volume meshes in core/GmshReader.cpp, membrane surfaces in structure/membrane/MembraneMeshImport.cpp)
/// only says what it does with each element block.
#include "core/Types.hpp"

#include <array>
#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace mfsi::gmsh {

/// \brief On which line an "unexpected end of file" is reported.
enum class EofLine {
  EndOfText,  ///< the line after the trailing whitespace (one past the last line when the file ends with a newline)
  LastToken,  ///< the line where reading stood before the trailing whitespace (the last line with content)
};

/// \brief Wording that differs between readers, so that each keeps the messages its users know.
struct MessageStyle {
  std::string fileKind = "Gmsh mesh file";  ///< "<path>: cannot open the <fileKind>"
  EofLine eofLine = EofLine::EndOfText;     ///< where the end of a truncated file is reported
  /// End of file while expecting a keyword: "while reading '$EndNodes'" (true) or "... $EndNodes".
  bool quoteExpectedKeyword = false;
  /// How to get an MSH 4.1 file, appended to the message for another version.
  std::string versionHint = "export with Gmsh's '-format msh41' option or Mesh.MshFileVersion = 4.1";
  std::string binaryHint = "save with Mesh.Binary = 0";  ///< how to get an ASCII file instead of a binary one
};

/// \brief Whitespace-separated tokens of an MSH file, with the line each one sits on. Every
/// reading call names what it expects (`what`), which ends up in the message when it fails;
/// failures throw InputError located at the file and line of the offending token.
class Lexer {
 public:
  /// \brief Tokens of `text`, which was read from `path` (named in messages).
  Lexer(std::string path, std::string text, MessageStyle style = {});

  /// \brief Tokens of the file `path`; throws InputError "<path>: cannot open the <fileKind>".
  static Lexer fromFile(const std::string& path, MessageStyle style = {});

  /// \brief True when only whitespace is left.
  bool atEnd();

  /// \brief Name the element being read in messages ("... of element <tag>"); -1: none.
  void setElement(long long tag) { element_ = tag; }

  /// \brief The next token.
  std::string_view next(std::string_view what);
  /// \brief The next token as an integer.
  long long integer(std::string_view what);
  /// \brief An integer that must fit a non-negative `int` (counts, types, dimensions).
  int count(std::string_view what);
  /// \brief The next token as a floating-point number (a leading '+' is accepted).
  double real(std::string_view what);
  /// \brief A "quoted string" (may contain spaces, not a newline), or a bare token.
  std::string quoted(std::string_view what);

  /// \brief The rest of the current line must be blank: catches elements with too many nodes.
  void expectLineEnd(std::string_view what);
  /// \brief Drop the rest of the current line.
  void skipLine();
  /// \brief Skip tokens up to and including `endToken`.
  void skipTo(const std::string& endToken);
  /// \brief The next token must be the keyword `token` (e.g. "$EndNodes").
  void expect(const std::string& token);

  /// \brief Characters not read yet.
  std::size_t remaining() const { return text_.size() - pos_; }
  /// \brief Line of the last token read.
  int line() const { return tokenLine_; }
  const std::string& path() const { return path_; }
  const MessageStyle& style() const { return style_; }

  /// \brief Throw InputError at the line of the last token read.
  [[noreturn]] void fail(const std::string& msg) const { failAt(tokenLine_, msg); }
  /// \brief Throw InputError at `line` of this file.
  [[noreturn]] void failAt(int line, const std::string& msg) const;

 private:
  std::string describe(std::string_view what) const;
  void skipSpace();

  std::string path_;
  std::string text_;
  MessageStyle style_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int tokenLine_ = 1;
  long long element_ = -1;
};

/// \brief (dimension, tag) of a physical group or an entity.
using DimTag = std::pair<int, int>;

/// \brief What the sections before the elements deliver.
struct MshData {
  std::map<DimTag, std::string> physicalNames;  ///< (dimension, physical tag) -> name
  int physicalNamesLine = 0;                    ///< line of the name count of $PhysicalNames (0: none)
  /// (dimension, entity tag) -> the entity's physical tags (made positive; Gmsh signs some for orientation).
  std::map<DimTag, std::vector<int>> entityPhysicals;
  std::vector<std::array<real, 3>> coords;         ///< node coordinates, in file order
  std::vector<long long> nodeTag;                  ///< node index -> Gmsh node tag
  std::unordered_map<long long, lid_t> nodeIndex;  ///< Gmsh node tag -> node index

  /// \brief The physical tags of entity (dim, tag); nullptr when it belongs to no physical group.
  const std::vector<int>* physicalsOf(int dim, int tag) const;
};

/// \brief The header of one block of $Elements.
struct ElementBlock {
  int dim = 0;     ///< dimension of the entity (0..3)
  int entity = 0;  ///< entity tag
  int type = 0;    ///< Gmsh element type
  int size = 0;    ///< number of elements in the block
  int line = 0;    ///< line of the block header
};

/// \brief Reads (or skips) all `size` elements of a block from the lexer that read its header.
using ElementBlockReader = std::function<void(const ElementBlock&)>;

/// \brief Read a whole MSH 4.1 ASCII file: $MeshFormat, $PhysicalNames, $Entities and $Nodes into
/// `d`; after the header of each block of $Elements, `readBlock` reads the block's elements from
/// `lx` (`d` then holds the nodes and entities read so far). Other sections are skipped.
///
/// Throws InputError naming the file and line for another version than 4.1 or a binary file, a
/// file that does not start with $MeshFormat, $Elements before $Nodes, malformed or truncated
/// content, duplicate node tags and counts that disagree with the section headers; and without a
/// line for an empty file or a missing $Nodes or $Elements section.
void readMsh41(Lexer& lx, MshData& d, const ElementBlockReader& readBlock);

/// \brief Skip `n` elements of a block (one element a line, as Gmsh writes them).
void skipElements(Lexer& lx, int n);

/// \brief Read a node tag of element `elementTag` (`what` names it in messages) and return its node
/// index; throws InputError "element <tag> refers to unknown node tag <t>" for a tag not in $Nodes.
lid_t readElementNode(Lexer& lx, const MshData& d, long long elementTag, std::string_view what);

/// \brief Name of a Gmsh element type for messages, e.g. "4-node tetrahedron" ("element of type
/// <type>" for a type without a name here).
std::string elementTypeName(long long type);

}  // namespace mfsi::gmsh
