// structure_doc.h over gemmi: the file read whole into memory (gemmi
// uncompresses .gz), checked where gemmi reads without checking, parsed, and
// the first model's atoms selected. Every exception stops here.
#include "structure_doc.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <strings.h>

#include <gemmi/gz.hpp>
#include <gemmi/mmcif.hpp>
#include <gemmi/mmread.hpp>
#include <gemmi/pdb.hpp>
#include <gemmi/resinfo.hpp>

#include "base/shim_error.h"

namespace {

struct Fault {
    std::string message;
};

// Whether the columns [start, end) of a fixed-column record hold a number,
// blanks around it allowed (blank == true: or nothing at all).
bool is_number_field(const char *line, size_t length, size_t start, size_t end, bool blank)
{
    std::string text(line + std::min(start, length), line + std::min(end, length));
    const size_t first = text.find_first_not_of(' ');
    if (first == std::string::npos)
        return blank;
    text = text.substr(first, text.find_last_not_of(' ') - first + 1);
    char *stop;
    const double value = std::strtod(text.c_str(), &stop);
    return *stop == '\0' && std::isfinite(value);
}

// gemmi compares record and residue names by shifting their chars as ints,
// which a byte above 0x7f (a negative char) makes undefined: such a byte is
// refused anywhere in the file, which the PDB archive writes in ASCII, in
// either format.
void check_ascii(const std::string &path, const char *data, size_t size)
{
    size_t line = 1;
    for (size_t i = 0; i < size; line += data[i++] == '\n')
        if (static_cast<unsigned char>(data[i]) > 0x7f)
            throw Fault{ path + ":" + std::to_string(line) +
                         ": not ASCII text, as PDB and mmCIF files are" };
}

// The lines of a PDB file as gemmi is to read them. gemmi reads some columns
// without checking that a line has them: every line is padded with blanks,
// which the fixed columns read as empty, to its 80 columns; and the
// connection records (SSBOND, LINK, CISPEP), whose columns gemmi reads past
// the end of its own trimmed copy of a line, are left out: no sphere depends
// on them.
std::string pdb_lines_for_gemmi(const char *data, size_t size)
{
    std::string out;
    out.reserve(size + size / 8);
    for (const char *line = data, *end = data + size; line < end;) {
        const char *next = static_cast<const char *>(std::memchr(line, '\n', end - line));
        size_t length = (next ? next : end) - line;
        if (length && line[length - 1] == '\r')
            length--;
        const auto is = [line, length](const char *record) {
            const size_t n = std::strlen(record);
            return length >= n && !strncasecmp(line, record, n);
        };
        if (is("SSBOND") || is("LINK") || is("CISPEP")) {
            line = next ? next + 1 : end;
            continue;
        }
        out.append(line, length);
        if (length < 80)
            out.append(80 - length, ' ');
        out += '\n';
        line = next ? next + 1 : end;
    }
    return out;
}

// gemmi reads a PDB atom's numbers without checking them (a letter reads as
// 0): each is checked here first, so that no sphere lands where the file did
// not put it; an atom line that ends before its coordinates is refused
// (padded_pdb_lines would give it blank ones).
void check_pdb_numbers(const std::string &path, const char *data, size_t size)
{
    static const struct {
        size_t start, end;
        const char *what;
        bool blank;
    } fields[] = {
        { 30, 38, "x", false }, { 38, 46, "y", false }, { 46, 54, "z", false },
        { 54, 60, "occupancy", true }, { 60, 66, "B-factor", true },
    };
    int number = 0;
    for (const char *line = data, *end = data + size; line < end; number++) {
        const char *next = static_cast<const char *>(std::memchr(line, '\n', end - line));
        size_t length = (next ? next : end) - line;
        if (length && line[length - 1] == '\r')
            length--;
        const bool atom = length >= 6 &&
                          (!std::strncmp(line, "ATOM  ", 6) || !std::strncmp(line, "HETATM", 6));
        if (atom && length < 54)
            throw Fault{ path + ":" + std::to_string(number + 1) + ": an atom line of " +
                         std::to_string(length) + " columns, short of its coordinates (31-54)" };
        if (atom)
            for (const auto &f : fields)
                if (!is_number_field(line, length, f.start, f.end, f.blank))
                    throw Fault{ path + ":" + std::to_string(number + 1) + ": " + f.what +
                                 " (columns " + std::to_string(f.start + 1) + "-" +
                                 std::to_string(f.end) + ") '" +
                                 std::string(line + f.start, line + std::min(f.end, length)) +
                                 "' is not a number" };
        line = next ? next + 1 : end;
    }
}

unsigned residue_kind(const gemmi::Residue &residue)
{
    const gemmi::ResidueInfo info = gemmi::find_tabulated_residue(residue.name);
    if (info.is_water())
        return PTR_STRUCTURE_WATER;
    if (info.is_amino_acid())
        return PTR_STRUCTURE_PROTEIN;
    if (info.is_nucleic_acid())
        return PTR_STRUCTURE_NUCLEIC;
    return PTR_STRUCTURE_LIGAND;
}

// One atom in several places: chain, residue number, insertion code, name.
using AtomKey = std::tuple<std::string, int, char, std::string>;

std::vector<StructureAtom> select_atoms(const std::string &path, const gemmi::Model &model,
                                        unsigned select, int hydrogens)
{
    std::vector<StructureAtom> atoms;
    std::map<AtomKey, size_t> first_of;
    for (const gemmi::Chain &chain : model.chains)
        for (const gemmi::Residue &residue : chain.residues) {
            if (!(residue_kind(residue) & select))
                continue;
            for (const gemmi::Atom &a : residue.atoms) {
                if (a.is_hydrogen() && !hydrogens)
                    continue;
                if (!std::isfinite(a.pos.x) || !std::isfinite(a.pos.y) ||
                    !std::isfinite(a.pos.z))
                    throw Fault{ path + ": atom " + std::to_string(a.serial) + " (" + a.name +
                                 " of " + residue.name + " " + residue.seqid.str() +
                                 ", chain " + chain.name + ") has no finite coordinates" };
                const StructureAtom atom = {
                    { a.pos.x, a.pos.y, a.pos.z }, a.element.atomic_number(), a.b_iso, a.occ,
                    a.serial };
                if (a.altloc) {
                    const AtomKey key{ chain.name, residue.seqid.num.value,
                                       residue.seqid.icode, a.name };
                    const auto found = first_of.find(key);
                    if (found != first_of.end()) {
                        StructureAtom &kept = atoms[found->second];
                        if (atom.occupancy > kept.occupancy)
                            kept = atom;
                        continue;
                    }
                    first_of.emplace(key, atoms.size());
                }
                atoms.push_back(atom);
            }
        }
    return atoms;
}

// gemmi reads an _atom_site without one of the columns it needs as no atoms:
// those missing are named instead.
void check_atom_site_columns(const std::string &path, const gemmi::cif::Block &block)
{
    static const char *const needed[] = {
        "id", "type_symbol", "label_alt_id", "label_asym_id", "Cartn_x", "Cartn_y",
        "Cartn_z", "occupancy", "B_iso_or_equiv", "auth_seq_id",
    };
    std::string missing;
    for (const char *column : needed)
        if (!block.has_tag(std::string("_atom_site.") + column))
            missing += (missing.empty() ? " " : ", ") + std::string(column);
    if (!missing.empty())
        throw Fault{ path + ": _atom_site lacks the columns" + missing };
}

// gemmi reads whole numbers in an int without checking their size (a signed
// overflow): a value whose leading digits could overflow one (ten or more) is
// refused before gemmi reads the block. No real number in a structure has
// them, whether whole or not.
bool could_overflow_int(const std::string &value)
{
    const size_t start = value.find_first_not_of(" +-");
    const size_t digits = value.find_first_not_of("0123456789", start == std::string::npos
                                                                    ? value.size() : start);
    return start != std::string::npos &&
           (digits == std::string::npos ? value.size() : digits) - start >= 10;
}

void check_whole_numbers(const std::string &path, const gemmi::cif::Block &block)
{
    const auto check = [&path](const std::string &value) {
        if (could_overflow_int(value))
            throw Fault{ path + ": '" + value.substr(0, 40) +
                         "' has more digits than a number in a structure can" };
    };
    for (const gemmi::cif::Item &item : block.items) {
        if (item.type == gemmi::cif::ItemType::Pair)
            check(item.pair[1]);
        else if (item.type == gemmi::cif::ItemType::Loop)
            for (const std::string &value : item.loop.values)
                check(value);
        else if (item.type == gemmi::cif::ItemType::Frame)
            check_whole_numbers(path, item.frame);
    }
}

// gemmi's messages name the file already; others get its name first.
PtrResult caught(PtrError *err, const std::string &path)
{
    try {
        throw;
    } catch (const std::runtime_error &e) {
        if (std::string(e.what()).rfind(path, 0) == 0)
            return ptr_shim_error(err, PTR_ERR_SCENE_INVALID, e.what());
        return ptr_shim_caught(err, PTR_ERR_SCENE_INVALID, path);
    } catch (...) {
        return ptr_shim_caught(err, PTR_ERR_SCENE_INVALID, path);
    }
}

} // namespace

extern "C" PtrResult structure_doc_read(const char *path, unsigned select, int hydrogens,
                                        StructureAtom **atoms, size_t *count, size_t *models,
                                        PtrError *err)
{
    try {
        gemmi::MaybeGzipped input(path);
        const gemmi::CoorFormat format = gemmi::coor_format_from_ext(input.basepath());
        if (format != gemmi::CoorFormat::Pdb && format != gemmi::CoorFormat::Mmcif)
            return ptr_shim_error(err, PTR_ERR_SCENE_INVALID,
                                  std::string(path) + ": not .pdb, .ent, .cif or .mmcif");
        gemmi::CharArray text = gemmi::read_into_buffer(input);
        check_ascii(path, text.data(), text.size());
        gemmi::Structure structure;
        if (format == gemmi::CoorFormat::Pdb) {
            check_pdb_numbers(path, text.data(), text.size());
            const std::string lines = pdb_lines_for_gemmi(text.data(), text.size());
            structure = gemmi::read_pdb_from_memory(lines.data(), lines.size(), path);
        } else {
            const gemmi::cif::Document doc = gemmi::cif::read_memory(text.data(), text.size(),
                                                                     path);
            if (!doc.blocks.empty()) {
                check_atom_site_columns(path, doc.blocks[0]);
                check_whole_numbers(path, doc.blocks[0]);
            }
            structure = gemmi::make_structure(doc);
        }
        text = gemmi::CharArray();
        if (structure.models.empty())
            return ptr_shim_error(err, PTR_ERR_SCENE_INVALID, std::string(path) + ": no atoms");
        std::vector<StructureAtom> kept =
            select_atoms(path, structure.models[0], select, hydrogens);
        StructureAtom *out = static_cast<StructureAtom *>(
            std::malloc((kept.size() ? kept.size() : 1) * sizeof *out));
        if (!out)
            return ptr_shim_error(err, PTR_ERR_NOMEM, std::string(path) + ": out of memory");
        std::copy(kept.begin(), kept.end(), out);
        *atoms = out;
        *count = kept.size();
        *models = structure.models.size();
        return PTR_OK;
    } catch (const Fault &fault) {
        return ptr_shim_error(err, PTR_ERR_SCENE_INVALID, fault.message);
    } catch (...) {
        return caught(err, path);
    }
}

extern "C" void structure_doc_free(StructureAtom *atoms)
{
    std::free(atoms);
}
