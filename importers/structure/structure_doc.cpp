// structure_doc.h over gemmi: the file read whole into memory (gemmi
// uncompresses .gz), checked where gemmi reads without checking, parsed, and
// the first model's atoms selected. Every exception stops here.
#include "structure_doc.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <strings.h>

#include <gemmi/gz.hpp>
#include <gemmi/mmcif.hpp>
#include <gemmi/mmread.hpp>
#include <gemmi/pdb.hpp>
#include <gemmi/polyheur.hpp>
#include <gemmi/resinfo.hpp>

#include "base/shim_error.h"

namespace {

struct Fault {
    std::string message;
    PtrResult code = PTR_ERR_SCENE_INVALID;
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
// on them. gemmi tells a record by its first four letters in any case
// ("SSBOX" is an SSBOND to it), and so are they told here.
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
        if (is("SSBO") || is("LINK") || is("CISP")) {
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

// gemmi reads the numbers of a PDB atom and of an assembly's operator
// (REMARK 350 BIOMT) without checking them (a letter reads as 0): each is
// checked here first, so that no sphere lands where the file did not put it;
// an atom line that ends before its coordinates is refused (padded_pdb_lines
// would give it blank ones).
struct NumberField {
    size_t start, end;
    const char *what;
    bool blank;
};

void check_fields(const std::string &path, int number, const char *line, size_t length,
                  const NumberField *fields, size_t count)
{
    for (const NumberField *f = fields; f < fields + count; f++)
        if (!is_number_field(line, length, f->start, f->end, f->blank))
            throw Fault{ path + ":" + std::to_string(number) + ": " + f->what + " (columns " +
                         std::to_string(f->start + 1) + "-" + std::to_string(f->end) + ") '" +
                         std::string(line + std::min(f->start, length),
                                     line + std::min(f->end, length)) +
                         "' is not a number" };
}

void check_pdb_numbers(const std::string &path, const char *data, size_t size)
{
    static const NumberField atom_fields[] = {
        { 30, 38, "x", false }, { 38, 46, "y", false }, { 46, 54, "z", false },
        { 54, 60, "occupancy", true }, { 60, 66, "B-factor", true },
    };
    static const NumberField operator_fields[] = {
        { 23, 33, "an operator's rotation", false }, { 33, 43, "an operator's rotation", false },
        { 43, 53, "an operator's rotation", false }, { 58, 68, "an operator's translation", false },
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
            check_fields(path, number + 1, line, length, atom_fields,
                         sizeof atom_fields / sizeof atom_fields[0]);
        if (length >= 18 && !std::strncmp(line, "REMARK 350", 10) &&
            !std::strncmp(line + 11, "  BIOMT", 7))
            check_fields(path, number + 1, line, length, operator_fields,
                         sizeof operator_fields / sizeof operator_fields[0]);
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

// One atom in several places: chain, subchain, residue number, insertion
// code, name. An atom's alternate locations are within one residue of one
// subchain (mmCIF label_asym_id); two subchains of one chain may number
// residues alike, and their atoms are not alternates of each other. An atom
// and the one it replaces thus share their part, whose count of atoms stays
// right.
using AtomKey = std::tuple<std::string, std::string, int, char, std::string>;

// The atoms kept, and the parts they belong to (StructureAtom.part): for
// each, its chain's name, its subchain's (which an assembly's generators
// name, from a PDB file and an mmCIF file respectively) and its atoms kept.
struct Selection {
    std::vector<StructureAtom> atoms;
    std::vector<std::pair<std::string, std::string>> parts;
    std::vector<size_t> part_atoms;
};

// The residues from the one at start to the one at end of the same chain,
// both included, marked kind; a record naming a residue the chain lacks
// marks none.
void mark_range(const gemmi::Model &model, const gemmi::AtomAddress &start,
                const gemmi::AtomAddress &end, unsigned char kind,
                std::map<const gemmi::Residue *, unsigned char> &secondary)
{
    for (const gemmi::Chain &chain : model.chains) {
        if (chain.name != start.chain_name || chain.name != end.chain_name)
            continue;
        const auto at = [&chain](const gemmi::SeqId &seqid) {
            size_t i = 0;
            while (i < chain.residues.size() && !(chain.residues[i].seqid == seqid))
                i++;
            return i;
        };
        const size_t first = at(start.res_id.seqid), last = at(end.res_id.seqid);
        for (size_t i = first; i <= last && last < chain.residues.size(); i++)
            secondary[&chain.residues[i]] = kind;
    }
}

// The secondary structure of the model's residues the file's HELIX and SHEET
// records (mmCIF: _struct_conf and _struct_sheet_range) name; coil is left
// out.
std::map<const gemmi::Residue *, unsigned char> secondary_structure(const gemmi::Structure &st,
                                                                   const gemmi::Model &model)
{
    std::map<const gemmi::Residue *, unsigned char> secondary;
    for (const gemmi::Helix &helix : st.helices)
        mark_range(model, helix.start, helix.end, STRUCTURE_HELIX, secondary);
    for (const gemmi::Sheet &sheet : st.sheets)
        for (const gemmi::Sheet::Strand &strand : sheet.strands)
            mark_range(model, strand.start, strand.end, STRUCTURE_SHEET, secondary);
    return secondary;
}

// Each subchain's entity: its number in st.entities.
std::map<std::string, unsigned> entity_numbers(const gemmi::Structure &st)
{
    std::map<std::string, unsigned> entity_of;
    for (size_t e = 0; e < st.entities.size(); e++)
        for (const std::string &subchain : st.entities[e].subchains)
            entity_of.emplace(subchain, static_cast<unsigned>(e));
    return entity_of;
}

Selection select_atoms(const std::string &path, const gemmi::Structure &st,
                       const gemmi::Model &model, unsigned select, int hydrogens)
{
    const std::map<const gemmi::Residue *, unsigned char> secondary =
        secondary_structure(st, model);
    const std::map<std::string, unsigned> entity_of = entity_numbers(st);
    std::map<std::string, unsigned> chain_numbers;
    std::map<std::pair<std::string, std::string>, unsigned> part_numbers;
    Selection kept;
    std::map<AtomKey, size_t> first_of;
    for (const gemmi::Chain &chain : model.chains) {
        const unsigned chain_number =
            chain_numbers.emplace(chain.name, static_cast<unsigned>(chain_numbers.size()))
                .first->second;
        for (const gemmi::Residue &residue : chain.residues) {
            if (!(residue_kind(residue) & select))
                continue;
            const auto structure = secondary.find(&residue);
            const auto entity = entity_of.find(residue.subchain);
            const auto part = part_numbers.emplace(std::make_pair(chain.name, residue.subchain),
                                                   static_cast<unsigned>(part_numbers.size()));
            if (part.second) {
                kept.parts.push_back(part.first->first);
                kept.part_atoms.push_back(0);
            }
            for (const gemmi::Atom &a : residue.atoms) {
                if (a.is_hydrogen() && !hydrogens)
                    continue;
                if (!std::isfinite(a.pos.x) || !std::isfinite(a.pos.y) ||
                    !std::isfinite(a.pos.z))
                    throw Fault{ path + ": atom " + std::to_string(a.serial) + " (" + a.name +
                                 " of " + residue.name + " " + residue.seqid.str() +
                                 ", chain " + chain.name + ") has no finite coordinates" };
                StructureAtom atom = {
                    { a.pos.x, a.pos.y, a.pos.z }, a.element.atomic_number(), a.b_iso, a.occ,
                    a.serial, {},
                    structure == secondary.end() ? static_cast<unsigned char>(STRUCTURE_COIL)
                                                 : structure->second,
                    chain_number,
                    entity == entity_of.end() ? static_cast<unsigned>(st.entities.size())
                                              : entity->second,
                    part.first->second };
                residue.name.copy(atom.residue, sizeof atom.residue - 1);
                if (a.altloc) {
                    const AtomKey key{ chain.name, residue.subchain, residue.seqid.num.value,
                                       residue.seqid.icode, a.name };
                    const auto found = first_of.find(key);
                    if (found != first_of.end()) {
                        StructureAtom &was = kept.atoms[found->second];
                        if (atom.occupancy > was.occupancy)
                            was = atom;
                        continue;
                    }
                    first_of.emplace(key, kept.atoms.size());
                }
                kept.atoms.push_back(atom);
                kept.part_atoms[atom.part]++;
            }
        }
    }
    return kept;
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

// An assembly as ptr builds it: for each generator, the names of the chains
// it applies to (a PDB file's chain names, an mmCIF file's subchains) and
// its operators.
struct Generator {
    std::vector<std::string> names;
    bool subchains;
    std::vector<gemmi::Transform> operators;
};

struct Assembly {
    std::string name;
    std::vector<Generator> generators;
};

// The lists of operator names an mmCIF oper_expression gives: "1", "1,3-5",
// "(1-60)", or a product of such lists in parentheses, "(1-60)(61-88)".
// Anything else is refused, and so is a range of more than
// STRUCTURE_MAX_INSTANCES operators, before gemmi reads the expression too
// (it makes every name of a range, unbounded, and reads each bound in an
// int without checking it).
std::vector<std::vector<std::string>> operator_lists(const std::string &path,
                                                     const std::string &expression)
{
    const auto fault = [&path, &expression](const char *why) {
        return Fault{ path + ": _pdbx_struct_assembly_gen.oper_expression '" +
                      expression.substr(0, 40) + "' " + why };
    };
    std::vector<std::string> texts;
    if (!expression.empty() && expression[0] == '(') {
        for (size_t at = 0; at < expression.size();) {
            const size_t close = expression.find(')', at);
            if (expression[at] != '(' || close == std::string::npos)
                throw fault("is not a list of operators or a product of lists");
            texts.push_back(expression.substr(at + 1, close - at - 1));
            at = close + 1;
        }
    } else {
        texts.push_back(expression);
    }
    const auto is_whole = [](const std::string &text) {
        return !text.empty() && text.size() <= 9 &&
               text.find_first_not_of("0123456789") == std::string::npos;
    };
    std::vector<std::vector<std::string>> lists;
    for (const std::string &text : texts) {
        lists.emplace_back();
        std::vector<std::string> items;
        gemmi::split_str_into(text, ',', items);
        for (const std::string &item : items) {
            const size_t dash = item.find('-');
            if (dash == std::string::npos) {
                if (item.empty() || item.find_first_of(" ()") != std::string::npos)
                    throw fault("names an operator without a name");
                lists.back().push_back(item);
                continue;
            }
            const std::string low = item.substr(0, dash), high = item.substr(dash + 1);
            if (!is_whole(low) || !is_whole(high) || std::stol(low) > std::stol(high))
                throw fault("has a range that is not one");
            if (std::stol(high) - std::stol(low) >= STRUCTURE_MAX_INSTANCES - 
                static_cast<long>(lists.back().size()))
                throw fault("names more operators than ptr builds (100000)");
            for (long n = std::stol(low); n <= std::stol(high); n++)
                lists.back().push_back(std::to_string(n));
        }
    }
    return lists;
}

// A generator's operators: the product of its lists, the last applied
// first, as the mmCIF dictionary defines it; refused before any is made if
// they are more than room, what STRUCTURE_MAX_INSTANCES leaves of its
// assembly.
std::vector<gemmi::Transform> operator_product(const std::string &path, const std::string &assembly,
                                               const std::vector<std::vector<std::string>> &lists,
                                               const std::map<std::string, gemmi::Transform> &known,
                                               size_t room)
{
    size_t count = 1;
    for (const std::vector<std::string> &list : lists)
        if ((count *= list.size()) > room)
            throw Fault{ path + ": assembly " + assembly +
                         " has more operators than ptr builds (100000)" };
    std::vector<gemmi::Transform> product(1);
    for (const std::vector<std::string> &list : lists) {
        std::vector<gemmi::Transform> next;
        for (const gemmi::Transform &left : product)
            for (const std::string &name : list) {
                const auto found = known.find(name);
                if (found == known.end())
                    throw Fault{ path + ": assembly " + assembly + ": operator '" + name +
                                 "' is not in _pdbx_struct_oper_list" };
                next.push_back(left.combine(found->second));
            }
        product.swap(next);
    }
    return product;
}

// An mmCIF file's assemblies, read here rather than by gemmi, which leaves
// out an operator the list lacks and reads only the first list of a product.
// Only the one asked for (see StructureRequest) gets its generators: a file
// of thousands of generators would otherwise have each expanded, however
// many operators they ask for in all; its operators are counted as they are
// made, and refused once they pass STRUCTURE_MAX_INSTANCES.
std::vector<Assembly> mmcif_assemblies(const std::string &path, gemmi::cif::Block &block,
                                       const char *asked)
{
    std::vector<std::string> tags = gemmi::impl::transform_tags("matrix", "vector");
    tags.emplace_back("id");
    std::map<std::string, gemmi::Transform> known;
    for (const auto row : block.find("_pdbx_struct_oper_list.", tags)) {
        gemmi::Transform t;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) {
                const double value = gemmi::cif::as_number(row[4 * i + j]);
                if (!std::isfinite(value))
                    throw Fault{ path + ": operator " + row.str(12) + ": '" +
                                 row[4 * i + j].substr(0, 40) + "' is not a number" };
                (j < 3 ? t.mat[i][j] : t.vec.at(i)) = value;
            }
        known.emplace(row.str(12), t);
    }
    std::vector<Assembly> assemblies;
    const auto named = [&assemblies](const std::string &name) -> Assembly & {
        for (Assembly &a : assemblies)
            if (a.name == name)
                return a;
        assemblies.push_back(Assembly{ name, {} });
        return assemblies.back();
    };
    for (const std::string &id : block.find_values("_pdbx_struct_assembly.id"))
        named(gemmi::cif::as_string(id));
    gemmi::cif::Table rows = block.find("_pdbx_struct_assembly_gen.",
                                        { "assembly_id", "oper_expression", "asym_id_list" });
    for (const auto row : rows)
        named(row.str(0));
    const auto chosen = std::find_if(assemblies.begin(), assemblies.end(),
                                     [asked, &assemblies](const Assembly &a) {
                                         return asked ? a.name == asked
                                                      : &a == &assemblies.front();
                                     });
    if (chosen == assemblies.end())
        return assemblies;
    size_t instances = 0;
    for (const auto row : rows) {
        if (row.str(0) != chosen->name)
            continue;
        Generator g{ {}, true, operator_product(path, chosen->name,
                                                operator_lists(path, row.str(1)), known,
                                                STRUCTURE_MAX_INSTANCES - instances) };
        instances += g.operators.size();
        gemmi::split_str_into(row.str(2), ',', g.names);
        chosen->generators.push_back(g);
    }
    return assemblies;
}

// A PDB file's assemblies (REMARK 350), as gemmi reads them.
std::vector<Assembly> pdb_assemblies(const gemmi::Structure &st)
{
    std::vector<Assembly> assemblies;
    for (const gemmi::Assembly &a : st.assemblies) {
        assemblies.push_back(Assembly{ a.name, {} });
        for (const gemmi::Assembly::Gen &gen : a.generators) {
            Generator g{ gen.chains, false, {} };
            for (const gemmi::Assembly::Operator &op : gen.operators)
                g.operators.push_back(op.transform);
            assemblies.back().generators.push_back(g);
        }
    }
    return assemblies;
}

// The assembly asked for (see StructureRequest), or none; checked against
// STRUCTURE_MAX_INSTANCES (a PDB file's, which gemmi made as it read them).
const Assembly *chosen_assembly(const std::string &path, const std::vector<Assembly> &assemblies,
                                const char *asked)
{
    const auto checked = [&path](const Assembly &a) {
        size_t operators = 0;
        for (const Generator &g : a.generators)
            operators += g.operators.size();
        if (operators > STRUCTURE_MAX_INSTANCES)
            throw Fault{ path + ": assembly " + a.name +
                         " has more operators than ptr builds (100000)" };
        return &a;
    };
    if (asked && !std::strcmp(asked, "none"))
        return nullptr;
    if (!asked)
        return assemblies.empty() ? nullptr : checked(assemblies[0]);
    std::string names;
    for (const Assembly &a : assemblies) {
        if (a.name == asked)
            return checked(a);
        if (names.size() < 60)
            names += (names.empty() ? "" : ", ") + a.name;
        else if (names.back() != '.')
            names += ", ...";
    }
    throw Fault{ path + ": no assembly '" + std::string(asked).substr(0, 40) +
                     "' (--assembly); it has " + (names.empty() ? "none" : names),
                 PTR_ERR_USAGE };
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

// The doc's assembly: its generators that hold atoms kept, with their parts
// and operators, each generator's atoms counted.
void fill_assembly(const Selection &kept, const Assembly &assembly,
                   std::vector<StructureGenerator> &generators, std::vector<unsigned> &parts,
                   std::vector<StructureOperator> &operators)
{
    // The parts of each chain name and of each subchain name, looked up by
    // the generators' names (a generator a name, not a part at a time: a
    // file's thousands of generators over thousands of chains stay quick).
    std::map<std::string, std::vector<unsigned>> of_chain, of_subchain;
    for (unsigned p = 0; p < kept.parts.size(); p++) {
        of_chain[kept.parts[p].first].push_back(p);
        of_subchain[kept.parts[p].second].push_back(p);
    }
    for (const Generator &g : assembly.generators) {
        StructureGenerator out = { parts.size(), 0, operators.size(), 0, 0 };
        const auto &of_name = g.subchains ? of_subchain : of_chain;
        for (const std::string &name : g.names) {
            const auto found = of_name.find(name);
            if (found != of_name.end())
                parts.insert(parts.end(), found->second.begin(), found->second.end());
        }
        // In the file's order, each part once, however often it is named.
        std::sort(parts.begin() + out.first_part, parts.end());
        parts.erase(std::unique(parts.begin() + out.first_part, parts.end()), parts.end());
        for (size_t k = out.first_part; k < parts.size(); k++)
            out.atoms += kept.part_atoms[parts[k]];
        out.part_count = parts.size() - out.first_part;
        if (!out.atoms || g.operators.empty()) {
            parts.resize(out.first_part);
            continue;
        }
        for (const gemmi::Transform &t : g.operators) {
            StructureOperator op;
            for (int i = 0; i < 3; i++) {
                for (int j = 0; j < 3; j++)
                    op.rotation[i][j] = t.mat[i][j];
                op.translation[i] = t.vec.at(i);
            }
            operators.push_back(op);
        }
        out.operator_count = g.operators.size();
        generators.push_back(out);
    }
}

// A copy of v in memory of malloc's (free's to give back), NULL if out of
// memory.
template <typename T> T *malloc_copy(const std::vector<T> &v)
{
    T *out = static_cast<T *>(std::malloc((v.size() ? v.size() : 1) * sizeof(T)));
    if (out)
        std::copy(v.begin(), v.end(), out);
    return out;
}

// The assemblies of a file read, or what reading them threw. A sequence of
// a file's models fails at each frame for an assembly it cannot read, as an
// import of one model does, while its models are still counted.
struct Assemblies {
    std::vector<Assembly> list;
    std::exception_ptr failed;
};

// Calls read (which returns the assemblies) into assemblies; what read
// throws is kept in it if keep_failure, else thrown.
template <typename Read> void read_assemblies(Assemblies &assemblies, bool keep_failure,
                                              Read read)
{
    try {
        assemblies.list = read();
    } catch (...) {
        if (!keep_failure)
            throw;
        assemblies.failed = std::current_exception();
    }
}

// The file read and parsed, checked where gemmi reads without checking;
// its assemblies (see Assembly, and mmcif_assemblies for asked) into
// assemblies, with their failure if keep_failure.
gemmi::Structure read_structure(const char *path, const char *asked, Assemblies &assemblies,
                                bool keep_failure)
{
    gemmi::MaybeGzipped input(path);
    const gemmi::CoorFormat format = gemmi::coor_format_from_ext(input.basepath());
    if (format != gemmi::CoorFormat::Pdb && format != gemmi::CoorFormat::Mmcif)
        throw Fault{ std::string(path) + ": not .pdb, .ent, .cif or .mmcif" };
    gemmi::CharArray text = gemmi::read_into_buffer(input);
    check_ascii(path, text.data(), text.size());
    if (format == gemmi::CoorFormat::Pdb) {
        check_pdb_numbers(path, text.data(), text.size());
        const std::string lines = pdb_lines_for_gemmi(text.data(), text.size());
        text = gemmi::CharArray();
        gemmi::Structure structure = gemmi::read_pdb_from_memory(lines.data(), lines.size(),
                                                                 path);
        read_assemblies(assemblies, keep_failure, [&] { return pdb_assemblies(structure); });
        return structure;
    }
    gemmi::cif::Document cif = gemmi::cif::read_memory(text.data(), text.size(), path);
    text = gemmi::CharArray();
    if (!cif.blocks.empty()) {
        check_atom_site_columns(path, cif.blocks[0]);
        check_whole_numbers(path, cif.blocks[0]);
        read_assemblies(assemblies, keep_failure,
                        [&] { return mmcif_assemblies(path, cif.blocks[0], asked); });
    }
    return gemmi::make_structure(cif);
}

} // namespace

// A file read for any of its models: gemmi's setup_entities, which cannot
// fail and does not depend on the model, has run once.
struct PtrStructureFile {
    gemmi::Structure structure; // its entities set up
    Assemblies assemblies;
};

extern "C" PtrResult structure_file_open(const char *path, const char *assembly,
                                         PtrStructureFile **out, PtrError *err)
{
    try {
        std::unique_ptr<PtrStructureFile> file(new PtrStructureFile);
        file->structure = read_structure(path, assembly, file->assemblies, true);
        gemmi::setup_entities(file->structure);
        *out = file.release();
        return PTR_OK;
    } catch (const Fault &fault) {
        return ptr_shim_error(err, fault.code, fault.message);
    } catch (...) {
        return caught(err, path);
    }
}

extern "C" size_t structure_file_models(const PtrStructureFile *file)
{
    return file->structure.models.size();
}

extern "C" void structure_file_free(PtrStructureFile *file)
{
    delete file;
}

extern "C" PtrResult structure_doc_read(const char *path, const StructureRequest *request,
                                        const PtrStructureFile *file, StructureDoc *doc,
                                        PtrError *err)
{
    try {
        PtrStructureFile read;
        if (!file) {
            read.structure = read_structure(path, request->assembly, read.assemblies, false);
            gemmi::setup_entities(read.structure);
            file = &read;
        }
        if (file->assemblies.failed)
            std::rethrow_exception(file->assemblies.failed);
        const gemmi::Structure &structure = file->structure;
        if (structure.models.empty())
            return ptr_shim_error(err, PTR_ERR_SCENE_INVALID, std::string(path) + ": no atoms");
        if (request->model >= structure.models.size())
            return ptr_shim_error(err, PTR_ERR_USAGE,
                                  std::string(path) + ": no model " +
                                      std::to_string(request->model + 1) + "; it has " +
                                      std::to_string(structure.models.size()));
        const Assembly *assembly =
            chosen_assembly(path, file->assemblies.list, request->assembly);
        const Selection kept = select_atoms(path, structure, structure.models[request->model],
                                            request->select, request->hydrogens);
        std::vector<StructureGenerator> generators;
        std::vector<unsigned> parts;
        std::vector<StructureOperator> operators;
        if (assembly)
            fill_assembly(kept, *assembly, generators, parts, operators);
        if (assembly && generators.empty() && !kept.atoms.empty())
            throw Fault{ path + std::string(": assembly ") + assembly->name +
                         " holds none of the atoms kept" };
        *doc = StructureDoc{ malloc_copy(kept.atoms), kept.atoms.size(), structure.models.size(),
                             malloc_copy(generators), generators.size(), malloc_copy(parts),
                             malloc_copy(operators) };
        if (!doc->atoms || !doc->generators || !doc->parts || !doc->operators) {
            structure_doc_free(doc);
            return ptr_shim_error(err, PTR_ERR_NOMEM, std::string(path) + ": out of memory");
        }
        return PTR_OK;
    } catch (const Fault &fault) {
        return ptr_shim_error(err, fault.code, fault.message);
    } catch (...) {
        return caught(err, path);
    }
}

extern "C" void structure_doc_free(StructureDoc *doc)
{
    std::free(doc->atoms);
    std::free(doc->generators);
    std::free(doc->parts);
    std::free(doc->operators);
    *doc = StructureDoc{};
}
