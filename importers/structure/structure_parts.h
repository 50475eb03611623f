/* The parts of a structure --select keeps (PtrImportOptions.structure_select),
 * told apart by residue name as gemmi tabulates them from the PDB's Chemical
 * Component Dictionary. Plain C and C++ both. */
#ifndef PTR_STRUCTURE_PARTS_H
#define PTR_STRUCTURE_PARTS_H

enum {
    PTR_STRUCTURE_PROTEIN = 1, /* amino acids, modified ones included */
    PTR_STRUCTURE_NUCLEIC = 2, /* nucleotides */
    PTR_STRUCTURE_LIGAND = 4,  /* every other residue */
    PTR_STRUCTURE_WATER = 8,
    PTR_STRUCTURE_ALL = 15,
    /* What --select keeps without being asked: waters hide what they
     * surround, and PyMOL and ChimeraX show structures without them. */
    PTR_STRUCTURE_DEFAULT = PTR_STRUCTURE_ALL & ~PTR_STRUCTURE_WATER,
};

#endif /* PTR_STRUCTURE_PARTS_H */
