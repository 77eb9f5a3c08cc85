//! Unit tests of the tree text parser.

use super::parse::{TreeFault, parse_tree};

#[test]
fn branches_and_grids_place_their_cells() {
    let text = "{ {1} {2} {3} {4} {5} {6} {7} { 0 1 2 3 4 5 6 7 } }";
    let tree = parse_tree(text, 3).unwrap();
    assert_eq!(tree.cells.len(), 15);
    assert_eq!(tree.depth, 2);
    // Child 1: upper half of dimension 0 only.
    assert_eq!(tree.cells[1].min, [0.5, 0.0, 0.0, 0.0]);
    assert_eq!(tree.cells[1].size, 0.5);
    // Child 7's grid: value 1 is the last dimension's upper half.
    let grid = &tree.cells[7..];
    assert_eq!(grid[1].min, [0.5, 0.5, 0.75, 0.0]);
    assert_eq!(grid[4].min, [0.75, 0.5, 0.5, 0.0]);
    assert_eq!(grid[4].value, 4.0);
}

#[test]
fn faults_give_their_offsets() {
    assert_eq!(
        parse_tree("{ 1 2 3 }", 3).err(),
        Some((2, TreeFault::Count(3)))
    );
    assert_eq!(
        parse_tree("{ 1 }}", 3).err(),
        Some((5, TreeFault::Syntax("text after the end of the tree")))
    );
    assert!(matches!(
        parse_tree("{ {1} {2} }", 3).err(),
        Some((10, TreeFault::Syntax("expected `{`")))
    ));
    assert_eq!(
        parse_tree("{ x }", 3).err(),
        Some((2, TreeFault::NotANumber("x".into())))
    );
    assert_eq!(
        parse_tree("{ -1 }", 4).err(),
        Some((2, TreeFault::Negative(-1.0)))
    );
    let deep = "{".repeat(30);
    assert_eq!(
        parse_tree(&deep, 3).err().map(|e| e.1),
        Some(TreeFault::TooDeep)
    );
    let tree = parse_tree("{ -1e-4 }", 3).unwrap();
    assert_eq!((tree.cells[0].value, tree.clipped), (0.0, 1));
}
